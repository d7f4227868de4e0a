"""The mechanism model: links, kinematic pairs and the graph they form.

A :class:`Mechanism` is a graph whose nodes are links (the frame among them) and whose edges are
kinematic pairs. Geometry lives in each link's own frame (docs/methods.md, "Poses and pair
equations"): a link's pose is the global position of its local origin and the angle of its local
x axis.

Build one with :class:`MechanismBuilder` (the scheme loader uses the same builder), e.g.

>>> from linkage.model.mechanism import MechanismBuilder
>>> b = MechanismBuilder("four_bar")
>>> _ = b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)})
>>> _ = b.link("1", line=("O", "A"), length=0.1)
>>> _ = b.link("2", line=("A", "B"), length=0.3)
>>> _ = b.link("3", line=("C", "B"), length=0.25)
>>> for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
...     _ = b.revolute(name, a, c)
>>> _ = b.inputs("1").assembly("B", left_of=("A", "C"))
>>> b.build().name
'four_bar'
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Mapping

import networkx as nx

from ..errors import SchemeError
from .input_laws import InputLaw, table_problems

__all__ = [
    "Guide",
    "Link",
    "Revolute",
    "Prismatic",
    "Assembly",
    "Output",
    "Mechanism",
    "MechanismBuilder",
    "InputCoordinate",
    "MAX_MAGNITUDE",
    "MIN_MAGNITUDE",
    "MAX_ANGLE_DEG",
    "MAX_POSITIONS",
    "check_number",
    "unknown_keys",
]

Vec = tuple[float, float]


@dataclass(frozen=True)
class Guide:
    """A straight guide line fixed in a link.

    Parameters
    ----------
    point : (float, float)
        A point of the line in the link's frame, m (any declared offset already applied).
    angle : float
        Direction of the line in the link's frame, rad (CCW from the link's x axis).
    """

    point: Vec
    angle: float

    @property
    def direction(self) -> Vec:
        return (math.cos(self.angle), math.sin(self.angle))


@dataclass(frozen=True)
class Link:
    """A rigid link.

    Parameters
    ----------
    name : str
        Unique name.
    points : mapping of str to (float, float)
        Named points in the link's own frame, m.
    guides : mapping of str to Guide
        Guide lines fixed in the link (for prismatic pairs where this link is the guide).
    mass : float
        kg (0 when not declared, see ``mass_declared``).
    center_of_mass : (float, float)
        Local coordinates of the centre of mass S, m.
    inertia : float
        Moment of inertia about S, kg m^2.
    mass_declared : bool
        False when the declaration gave no mass (treated as zero, with a note in reports).
    """

    name: str
    points: Mapping[str, Vec] = field(default_factory=dict)
    guides: Mapping[str, Guide] = field(default_factory=dict)
    mass: float = 0.0
    center_of_mass: Vec = (0.0, 0.0)
    inertia: float = 0.0
    mass_declared: bool = False


@dataclass(frozen=True)
class Revolute:
    """A revolute (turning) pair joining ``links[0]`` and ``links[1]`` at the point ``point``.

    The point of that name must be declared on both links.
    """

    name: str
    links: tuple[str, str]
    point: str
    kind = "R"


@dataclass(frozen=True)
class Prismatic:
    """A prismatic (sliding) pair: ``links[1]`` (the slider) slides along a guide of ``links[0]``.

    Parameters
    ----------
    name : str
        Unique pair name.
    links : (str, str)
        (guide link, slider link).
    guide : str
        Name of the guide line on the guide link.
    point : str
        The slider's point that stays on the guide line.
    angle : float
        Fixed angle of the slider's x axis relative to the guide direction, rad (beta in docs/methods.md).
    """

    name: str
    links: tuple[str, str]
    guide: str
    point: str
    angle: float = 0.0
    kind = "P"


@dataclass(frozen=True)
class Assembly:
    """A readable assembly condition that picks a group's branch.

    ``rule`` is one of

    - ``"left_of"`` / ``"right_of"``: ``point`` lies left / right of the directed line
      ``refs[0] -> refs[1]``;
    - ``"towards"``: ``point`` lies from ``refs[0]`` in the direction ``angle`` (rad), i.e.
      ``(P - X) . (cos angle, sin angle) > 0``;
    - ``"branch"``: the raw branch sign ``M = value`` of the group's solver (documented per kind).

    ``phi`` (rad), when given, is the input angle at which the condition holds; otherwise it
    holds at most input angles of a turn.

    ``mode`` says what happens where the group's two assembly modes meet (a change point, where
    the group passes a singular position and may go on in either mode): ``"keep"`` keeps the
    declared branch of the closed form (the mechanism switches mode there, with a
    ``BranchWarning``); ``"follow"`` follows the motion continuously through it.
    """

    point: str
    rule: str
    refs: tuple[str, ...] = ()
    angle: float = 0.0
    value: int = 1
    mode: str = "keep"
    phi: float | None = None


@dataclass(frozen=True)
class Output:
    """The output coordinate that defines extreme positions and the start of tables.

    ``quantity`` is ``"P.x"``, ``"P.y"`` (point), ``"L.theta"`` (link angle) or ``"K.s"``
    (slide of prismatic pair K); ``start`` is ``"max"`` or ``"min"``: which extreme position
    starts the cycle.
    """

    quantity: str
    start: str = "max"


@dataclass(frozen=True)
class InputCoordinate:
    """The generalized coordinate of an input: a crank's angle or a slide.

    ``kind`` is ``"angle"`` (a crank pinned to the frame: rad, shown in deg, periodic over a turn)
    or ``"slide"`` (a slider driven along a frame guide, or a cylinder's extension between two
    links: m, shown in m, not periodic, analysed over a declared stroke). The analogs of every
    quantity are derivatives with respect to the first input's coordinate (per rad or per m), and
    an input's balancing load is a moment (N m) or a force (N) accordingly (docs/inputs.md).
    """

    kind: str = "angle"

    @property
    def is_angle(self) -> bool:
        return self.kind == "angle"

    @property
    def symbol(self) -> str:
        """``"phi"`` or ``"s"``."""
        return "phi" if self.is_angle else "s"

    @property
    def unit(self) -> str:
        """SI unit of the coordinate: ``"rad"`` or ``"m"``."""
        return "rad" if self.is_angle else "m"

    @property
    def shown_unit(self) -> str:
        """Unit of the coordinate in tables and messages: ``"deg"`` or ``"m"``."""
        return "deg" if self.is_angle else "m"

    @property
    def period(self) -> float | None:
        """``2 pi`` for an angle, None for a slide."""
        return 2 * math.pi if self.is_angle else None

    @property
    def load(self) -> str:
        """What balances the input: ``"moment"`` (N m) or ``"force"`` (N)."""
        return "moment" if self.is_angle else "force"

    def shown(self, values):
        """Values of the coordinate in the unit of tables and messages (deg or m)."""
        import numpy as np

        return np.degrees(values) if self.is_angle else np.asarray(values, dtype=float)

    def describe(self, values, limit: int = 20) -> str:
        """``"input angle(s) (deg): 10, 20"`` or ``"input slide(s) (m): 0.1, 0.2"`` for values in
        the SI unit (at most ``limit`` shown)."""
        values = list(self.shown(values))
        shown = ", ".join(f"{v:.6g}" for v in values[:limit]) + (" ..." if len(values) > limit else "")
        return f"input {self.kind}(s) ({self.shown_unit}): {shown}"


@dataclass(frozen=True, eq=True)
class Mechanism:
    """A planar mechanism with lower pairs.

    Use :class:`MechanismBuilder` or :func:`linkage.load` to make one: they validate it.

    ``input_range`` ``(a, b)`` (rad), when given, is the range of the input angle over which the
    mechanism is analysed (a mechanism whose input does not turn fully: a rocker input, a
    tangent mechanism): tables run from ``a`` to ``b``, extreme positions are searched within
    it, and computations over a full turn (cycle dynamics) refuse it. None: a full turn.

    ``input_laws`` maps each input link after the first to the law its angle follows as a function
    of the first input's angle ``phi`` (:class:`~linkage.model.input_laws.InputLaw`; mobility W > 1).

    An input is named by a link or by a pair (:meth:`input_pair`): a link pinned to the frame is
    a crank (its angle is the coordinate); a link in a prismatic pair with the frame, or a
    prismatic pair itself, is driven by its slide (m; a pair between two moving links is a
    cylinder's extension). The first input's coordinate (:attr:`coordinate`) is what ``phi`` of
    every analysis holds (rad or m); a slide needs ``input_range``, the stroke (m).
    """

    name: str
    links: Mapping[str, Link]
    pairs: Mapping[str, Revolute | Prismatic]
    inputs: tuple[str, ...]
    frame: str = "0"
    assembly: tuple[Assembly, ...] = ()
    output: Output | None = None
    description: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict, compare=True)
    input_range: tuple[float, float] | None = None
    input_laws: Mapping[str, InputLaw] = field(default_factory=dict)

    #: What later stages derive from the mechanism alone and keep, by key (``"structure"``: its
    #: decomposition; ``"plans"``: assembly plans; ``"extremes"``; ``"parts"``): computed on
    #: first use, never part of the mechanism's identity (equality, hash) or its declaration.
    cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __hash__(self) -> int:
        """Hash of what names the mechanism, consistent with equality (equal mechanisms have
        equal names, frames, inputs, links and pairs)."""
        return hash((self.name, self.frame, self.inputs, tuple(sorted(self.links)), tuple(sorted(self.pairs))))

    @property
    def parts(self) -> dict[str, Any]:
        """Typed parts parsed once from the further sections of ``extra`` (``"loads"`` ->
        :class:`~linkage.kinetostatics.loads.Loads`, ``"dynamics"`` -> a ``DynamicsSpec`` or
        None): filled when a scheme is loaded, or on first use by
        :func:`linkage.model.scheme.section_of`; kept in :attr:`cache`."""
        return self.cache.setdefault("parts", {})

    @cached_property
    def graph(self) -> nx.MultiGraph:
        """Links as nodes (attribute ``link``), pairs as edges (key = pair name, ``pair``)."""
        g = nx.MultiGraph(name=self.name)
        for name in sorted(self.links):
            g.add_node(name, link=self.links[name])
        for name in sorted(self.pairs):
            pair = self.pairs[name]
            g.add_edge(*pair.links, key=name, pair=pair)
        return g

    @cached_property
    def size(self) -> float:
        """Characteristic length, m: the largest distance between two points of one link."""
        size = 0.0
        for link in self.links.values():
            pts = list(link.points.values()) + [g.point for g in link.guides.values()]
            for i, p in enumerate(pts):
                for q in pts[i + 1 :]:
                    size = max(size, math.dist(p, q))
        return size if size > 0 else 1.0

    def input_pair(self, name: str) -> str | None:
        """The pair that drives the input ``name``: the pair itself when ``name`` is a pair; for a
        link, its revolute pair with the frame (the first by name), else its prismatic pair with
        the frame; None when there is none."""
        if name in self.pairs:
            return name
        frame_pairs = sorted(k for k, p in self.pairs.items() if set(p.links) == {name, self.frame})
        for kind in (Revolute, Prismatic):
            found = [k for k in frame_pairs if isinstance(self.pairs[k], kind)]
            if found:
                return found[0]
        return None

    def input_kind(self, name: str) -> str:
        """``"angle"`` for an input driven by a revolute pair, ``"slide"`` for a prismatic one."""
        pair = self.pairs.get(self.input_pair(name) or "")
        return "slide" if isinstance(pair, Prismatic) else "angle"

    @property
    def coordinate(self) -> InputCoordinate:
        """The first input's coordinate (an angle or a slide): what ``phi`` holds."""
        return InputCoordinate(self.input_kind(self.inputs[0]) if self.inputs else "angle")

    def point_link(self, point: str) -> str:
        """Name of the link that reports the position of ``point`` (frame first, then by name)."""
        owners = self.point_links(point)
        if not owners:
            raise SchemeError(f"mechanism '{self.name}': unknown point '{point}'")
        return owners[0]

    def point_links(self, point: str) -> list[str]:
        """All links declaring ``point``, frame first, then sorted by name."""
        owners = sorted(n for n, lk in self.links.items() if point in lk.points)
        if self.frame in owners:
            owners.remove(self.frame)
            owners.insert(0, self.frame)
        return owners

    @cached_property
    def point_names(self) -> list[str]:
        """Every named point, sorted."""
        return sorted({p for lk in self.links.values() for p in lk.points})

    @property
    def output_point(self) -> str | None:
        """The point of the declared output (``B`` of ``B.x``) when the output is a point's
        coordinate, else None."""
        if self.output is None:
            return None
        name, _, coord = self.output.quantity.rpartition(".")
        return name if coord in ("x", "y") and name in self.point_names else None

    @property
    def moving_links(self) -> list[str]:
        return sorted(n for n in self.links if n != self.frame)

    def with_extra(self, **extra: Any) -> "Mechanism":
        """A copy with more entries in ``extra`` (loads, dynamics inputs declared by schemes)."""
        merged = dict(self.extra)
        merged.update(extra)
        return Mechanism(
            self.name, self.links, self.pairs, self.inputs, self.frame, self.assembly,
            self.output, self.description, merged, self.input_range, self.input_laws,
        )

    def with_input_laws(self, **laws: InputLaw) -> "Mechanism":
        """A copy whose further input links follow the given laws (the others keep theirs),
        validated; its further sections (loads, dynamics) are parsed again on first use, since
        their stroke ends depend on the motion. Raises :class:`SchemeError` naming the problems."""
        copy = Mechanism(self.name, self.links, self.pairs, self.inputs, self.frame, self.assembly,
                         self.output, self.description, dict(self.extra), self.input_range,
                         {**self.input_laws, **laws})
        problems = [f"mechanism '{self.name}': {p}" for p in _law_problems(copy)]
        if problems:
            raise SchemeError(problems)
        return copy


# ----------------------------------------------------------------------------------------------
# Builder: the one way to declare a mechanism (the scheme loader calls it too)
# ----------------------------------------------------------------------------------------------


#: Largest magnitude of a number in a declaration (a length, coordinate, mass, inertia, force,
#: moment, speed, ratio ...). The pipeline multiplies up to six declared numbers (a kinetic energy
#: ``m l^2 omega^2`` has five factors, a dyad's Jacobian determinant three lengths); with every
#: factor within [1e-50, 1e50] such a product stays within [1e-300, 1e300]: finite, and above the
#: smallest normal float64 (2.2e-308). Documented in ``schemes/README.md`` ("Ranges").
MAX_MAGNITUDE = 1e50
#: Smallest magnitude of a number that must be positive or nonzero because it sets a scale or
#: divides (a link's length, a speed, a gear ratio ...); see :data:`MAX_MAGNITUDE`.
MIN_MAGNITUDE = 1e-50
#: Largest magnitude of an angle, degrees: beyond it a float64 no longer holds the angle to
#: 1e-10 of a degree (its spacing at 1e6 is 1.2e-10).
MAX_ANGLE_DEG = 1e6

#: Largest number of positions per revolution of a table (and of table positions a scheme's
#: ``[dynamics]`` may declare): the arrays grow with it.
MAX_POSITIONS = 100_000

_RANGES = {
    # kind: (test, description)
    "real": (lambda v: abs(v) <= MAX_MAGNITUDE, f"a number with |x| <= {MAX_MAGNITUDE:g}"),
    "nonnegative": (lambda v: 0 <= v <= MAX_MAGNITUDE, f"a number in [0, {MAX_MAGNITUDE:g}]"),
    "positive": (lambda v: MIN_MAGNITUDE <= v <= MAX_MAGNITUDE,
                 f"a number in [{MIN_MAGNITUDE:g}, {MAX_MAGNITUDE:g}]"),
    "nonzero": (lambda v: MIN_MAGNITUDE <= abs(v) <= MAX_MAGNITUDE,
                f"a nonzero number with {MIN_MAGNITUDE:g} <= |x| <= {MAX_MAGNITUDE:g}"),
    "angle_deg": (lambda v: abs(v) <= MAX_ANGLE_DEG, f"a number with |x| <= {MAX_ANGLE_DEG:g}"),
    "angle": (lambda v: abs(v) <= math.radians(MAX_ANGLE_DEG),
              f"a number with |x| <= {math.radians(MAX_ANGLE_DEG):.6g}"),
    "fraction": (lambda v: 0 <= v <= 1, "a number in [0, 1]"),
}


def check_number(value: Any, where: str, what: str, problems: list[str], kind: str = "real",
                 unit: str = "") -> float | None:
    """``float(value)`` when it is a finite number in the range ``kind``; else None, with a problem.

    Parameters
    ----------
    value : Any
        The declared value.
    where, what : str
        The entry (``"link '2'"``, ``"pairs.slide"``) and the key (``"length"``) for the message.
    problems : list of str
        Where the problem is appended.
    kind : {"real", "nonnegative", "positive", "nonzero", "angle_deg", "angle", "fraction"}
        The range (see :data:`MAX_MAGNITUDE` and ``schemes/README.md``).
    unit : str
        Unit shown in the message ("m", "kg").

    Returns
    -------
    float or None

    Examples
    --------
    >>> problems = []
    >>> check_number(1e200, "link '2'", "length", problems, "positive", "m")
    >>> problems
    ["link '2': length must be a number in [1e-50, 1e+50] m, got 1e+200"]
    """
    test, description = _RANGES[kind]
    if _is_number(value) and test(value):
        return float(value)
    problems.append(f"{where + ': ' if where else ''}{what} must be {description}{' ' + unit if unit else ''}, got {value!r}")
    return None


def unknown_keys(spec: Mapping[str, Any], known, where: str, problems: list[str]) -> set[str]:
    """Report the keys of ``spec`` that are not in ``known``, suggesting the known key meant.

    Returns the known keys that ``spec`` lacks and that an unknown key looks like a misspelling
    of (``{"links"}`` for ``link``): the entry is then incomplete, and the caller may skip it
    instead of reporting the missing key as a second problem of the same cause.

    Examples
    --------
    >>> problems = []
    >>> unknown_keys({"link": ["1", "2"]}, {"links", "kind", "at"}, "pairs.A", problems)
    {'links'}
    >>> problems
    ["pairs.A: unknown keys ['link'] (known: ['at', 'kind', 'links']); did you mean 'links'?"]
    """
    bad = sorted(k for k in spec if k not in known)
    if not bad:
        return set()
    absent = sorted(k for k in known if k not in spec)
    meant = [m[0] for m in (difflib.get_close_matches(str(k), absent, n=1, cutoff=0.6) for k in bad) if m]
    hint = f"; did you mean {', '.join(repr(m) for m in meant)}?" if meant else ""
    problems.append(f"{where + ': ' if where else ''}unknown keys {bad} (known: {sorted(known)}){hint}")
    return set(meant)


def _angle(spec: Mapping[str, Any], key: str, where: str, problems: list[str], default=0.0):
    """Read ``key`` (rad) or ``key_deg`` (deg) from ``spec``; return radians."""
    has_rad, has_deg = key in spec, f"{key}_deg" in spec
    if has_rad and has_deg:
        problems.append(f"{where}: give either '{key}' or '{key}_deg', not both")
        return default
    raw = spec.get(key, spec.get(f"{key}_deg", None))
    if raw is None:
        return default
    name = f"{key}_deg" if has_deg else key
    value = check_number(raw, where, f"'{name}'", problems, "angle_deg" if has_deg else "angle",
                         "deg" if has_deg else "rad")
    if value is None:
        return default
    return math.radians(value) if has_deg else value


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _vector(raw: Any) -> Vec | None:
    if isinstance(raw, (list, tuple)) and len(raw) == 2 and all(_is_number(v) for v in raw):
        return (float(raw[0]), float(raw[1]))
    return None


def _coordinates(raw: Any, where: str, expected: str, problems: list[str]) -> Vec | None:
    """``(x, y)`` of a declared ``[x, y]``, or None with a problem: not a pair of finite numbers
    (the message says ``expected``), or a coordinate out of range (:data:`MAX_MAGNITUDE`)."""
    vec = _vector(raw)
    if vec is None:
        problems.append(f"{where}: expected {expected}, got {raw!r}")
    elif not all(abs(c) <= MAX_MAGNITUDE for c in vec):
        problems.append(f"{where}: coordinates must be numbers with |x| <= {MAX_MAGNITUDE:g} m, got {raw!r}")
        vec = None
    return vec


class MechanismBuilder:
    """Declare a mechanism step by step, then :meth:`build` it (validated, all problems at once).

    Every method returns the builder so calls can be chained. Lengths in m, angles in rad
    (or ``*_deg`` keys in point / guide specifications), masses in kg.
    """

    def __init__(self, name: str, description: str = "", frame: str = "0"):
        self.name = name
        self.description = description
        self.frame = frame
        self._links: dict[str, Link] = {}
        self._pairs: dict[str, Revolute | Prismatic] = {}
        self._inputs: list[str] = []
        self._laws: dict[str, InputLaw] = {}
        self._law_degrees: dict[str, tuple[str, ...]] = {}
        self._assembly: list[Assembly] = []
        self._output: Output | None = None
        self._range: tuple[float, float] | None = None
        self._range_in_degrees = False
        self._range_given: str | None = None
        self._problems: list[str] = []
        self._rejected: set[str] = set()  # links and pairs refused (reported already)
        self._unplaced: dict[str, set[str]] = {}  # link -> its points and guides refused
        self._incomplete: set[str] = set()  # links whose refused line leaves its points unknown
        self._inputs_refused = False

    # -- links ---------------------------------------------------------------------------------
    def link(
        self,
        name: str,
        *,
        line: tuple[str, str] | None = None,
        length: float | None = None,
        points: Mapping[str, Any] | None = None,
        guides: Mapping[str, Any] | None = None,
        mass: float | None = None,
        com: str | Vec | None = None,
        inertia: float | None = None,
    ) -> "MechanismBuilder":
        """Declare a link.

        Parameters
        ----------
        name : str
            Link name (the frame is ``self.frame``, "0" by default).
        line, length : (str, str), float
            A binary link by its length: ``line[0]`` at the local origin, ``line[1]`` at
            ``(length, 0)``; the local x axis runs along the line.
        points : mapping
            More points: ``(x, y)`` in the link's frame, or ``{"from": P, "distance": d,
            "angle_deg": a}`` -- at distance d from point P, at angle a CCW from the link's x axis.
        guides : mapping
            Guide lines: ``{"through": P or (x, y), "angle_deg": a, "offset": e}``: through the
            point, at angle a from the link's x axis, shifted by e along the line's left normal.
        mass, com, inertia : float, str or (x, y), float
            Mass (kg), centre of mass (a point name or local coordinates), J_S (kg m^2).
        """
        where = f"link '{name}'"
        p = self._problems
        if name in self._links:
            p.append(f"{where}: declared twice")
            return self
        local: dict[str, Vec] = {}
        unplaced = self._unplaced.setdefault(name, set())  # declared, but refused: no follow-ons
        if line is not None or length is not None:
            if not isinstance(line, (tuple, list)) or len(line) != 2 or not all(isinstance(s, str) for s in line):
                p.append(f"{where}: 'line' must name two points, got {line!r}")
                self._incomplete.add(name)  # its points are unknown: no follow-ons about them
            elif line[0] == line[1]:
                p.append(f"{where}: 'line' joins point '{line[0]}' to itself")
                unplaced.add(line[0])
            else:
                value = check_number(length, where, "length", p, "positive", "m")
                if value is None:
                    unplaced.update(line)
                else:
                    local[line[0]] = (0.0, 0.0)
                    local[line[1]] = (value, 0.0)
        # names whose absence is reported already: refused ones (or all, when the line is unknown)
        missing = _EVERY_NAME if name in self._incomplete else unplaced
        for pname, spec in (points or {}).items():
            pwhere = f"{where} point '{pname}'"
            if pname in local:
                p.append(f"{pwhere}: declared twice")
                continue
            if isinstance(spec, Mapping):
                vec = self._relative_point(spec, local, missing, pwhere)
            else:
                vec = _coordinates(spec, pwhere, "[x, y] or {from, distance, angle_deg}", p)
            if vec is None:
                unplaced.add(pname)
            else:
                local[pname] = vec
        link_guides: dict[str, Guide] = {}
        for gname, spec in (guides or {}).items():
            gwhere = f"{where} guide '{gname}'"
            guide = self._guide(spec, local, missing, gwhere)
            if guide is None:
                unplaced.add(gname)
            else:
                link_guides[gname] = guide
        ok_mass = mass is None or check_number(mass, where, "mass", p, "nonnegative", "kg") is not None
        ok_inertia = inertia is None or check_number(inertia, where, "inertia", p, "nonnegative",
                                                     "kg m^2") is not None
        center: Vec = (0.0, 0.0)
        if isinstance(com, str):
            if com in local:
                center = local[com]
            elif com not in missing:
                p.append(f"{where}: centre of mass must be a point of the link or [x, y], got {com!r}")
        elif com is not None:
            center = _coordinates(com, where + " centre of mass", "a point of the link or [x, y]", p) or center
        elif ok_mass and mass:
            p.append(f"{where}: mass {mass} kg is given without a centre of mass ('com')")
        self._links[name] = Link(
            name,
            local,
            link_guides,
            float(mass) if mass is not None and ok_mass else 0.0,
            center,
            float(inertia) if inertia is not None and ok_inertia else 0.0,
            mass is not None,
        )
        return self

    def _relative_point(self, spec: Mapping[str, Any], local: dict[str, Vec], unplaced, where: str) -> Vec | None:
        p = self._problems
        unknown_keys(spec, {"from", "distance", "angle", "angle_deg"}, where, p)
        origin = spec.get("from")
        if not isinstance(origin, str) or origin not in local:
            if not (isinstance(origin, str) and origin in unplaced):  # else: reported already
                p.append(f"{where}: 'from' must name an earlier point of the link, got {origin!r}")
            return None
        distance = check_number(spec.get("distance"), where, "distance", p, "nonnegative", "m")
        angle = _angle(spec, "angle", where, p)
        if distance is None:
            return None
        ox, oy = local[origin]
        return (ox + distance * math.cos(angle), oy + distance * math.sin(angle))

    def _guide(self, spec: Any, local: dict[str, Vec], unplaced, where: str) -> Guide | None:
        p = self._problems
        if not isinstance(spec, Mapping):
            p.append(f"{where}: expected {{through, angle_deg, offset}}, got {spec!r}")
            return None
        unknown_keys(spec, {"through", "angle", "angle_deg", "offset"}, where, p)
        through = spec.get("through", (0.0, 0.0))
        if isinstance(through, str):
            base = local.get(through)
            if base is None and through not in unplaced:
                p.append(f"{where}: 'through' must be a point of the link or [x, y], got {through!r}")
        else:
            base = _coordinates(through, where, "'through' = a point of the link or [x, y]", p)
        angle = _angle(spec, "angle", where, p)
        offset = check_number(spec.get("offset", 0.0), where, "offset", p, "real", "m")
        if base is None or offset is None:
            return None
        nx_, ny_ = -math.sin(angle), math.cos(angle)
        return Guide((base[0] + offset * nx_, base[1] + offset * ny_), angle)

    # -- pairs ---------------------------------------------------------------------------------
    def revolute(self, name: str, link_a: str, link_b: str, at: str | None = None) -> "MechanismBuilder":
        """Pin ``link_a`` and ``link_b`` at the point ``at`` (default: the pair's name)."""
        if self._check_pair_name(name):
            self._pairs[name] = Revolute(name, (link_a, link_b), at if at is not None else name)
        return self

    def prismatic(
        self, name: str, guide_link: str, slider_link: str, *, guide: str, at: str, angle: float = 0.0
    ) -> "MechanismBuilder":
        """Let ``slider_link``'s point ``at`` slide on guide ``guide`` of ``guide_link``.

        ``angle`` is the fixed angle of the slider's x axis to the guide direction (rad).
        """
        value = check_number(angle, f"pair '{name}'", "angle", self._problems, "angle", "rad")
        if value is None:
            self._rejected.add(name)
        elif self._check_pair_name(name):
            self._pairs[name] = Prismatic(name, (guide_link, slider_link), guide, at, value)
        return self

    def reject(self, name: str | None = None, names=(), *, inputs: bool = False) -> "MechanismBuilder":
        """Note that a declaration was refused by the caller, who has reported why (a misspelt key
        in a scheme file, say): the link or pair ``name`` (with the points and guides ``names`` it
        declares), or, with ``inputs``, the input links.

        :meth:`build` then leaves out the problems that only follow from its absence (pairs that
        join it, its points, the input's frame pair, "no input link"): one message per root cause.
        """
        if name is not None:
            self._rejected.add(name)
            self._unplaced.setdefault(name, set()).update(n for n in names if isinstance(n, str))
        self._inputs_refused = self._inputs_refused or inputs
        return self

    def _check_pair_name(self, name: str) -> bool:
        if name in self._pairs:
            self._problems.append(f"pair '{name}': declared twice")
            return False
        return True

    # -- the rest ------------------------------------------------------------------------------
    def inputs(self, *links: str) -> "MechanismBuilder":
        """Declare the input links (cranks), each pinned to the frame. The first one's angle is
        ``phi``; each further one turns by its :meth:`input_law`."""
        self._inputs.extend(links)
        return self

    def input_law(self, link: str, *, ratio: float | None = None, phase: float | None = None,
                  table=None, degrees=()) -> "MechanismBuilder":
        """The angle of the further input ``link`` as a function of the first input's ``phi``:
        ``ratio * phi + phase`` (rad; defaults 1 and 0), or ``table=(phi, theta)``, two sequences of
        angles (rad) interpolated by a cubic spline (see :class:`~linkage.model.input_laws.InputLaw`).
        For a further input that is a slide, its slide (m) ``ratio * phi + phase`` (phase in m; no
        table). ``degrees``: the scheme keys given in degrees (``phase_deg``, ``table_deg``), which
        a slide refuses."""
        if degrees:
            self._law_degrees[link] = tuple(degrees)
        where = f"input law of link '{link}'"
        if link in self._laws:
            self._problems.append(f"{where}: declared twice")
            return self
        if table is not None:
            found = table_problems(where, table) + ([f"{where}: give either a table or a ratio and a phase, not both"]
                                                    if ratio is not None or phase is not None else [])
            self._problems.extend(found)
            if not found:
                self._laws[link] = InputLaw(table=tuple(tuple(float(v) for v in column) for column in table))
            return self
        found: list[str] = []
        ratio = 1.0 if ratio is None else check_number(ratio, where, "ratio", found, "nonzero")
        phase = 0.0 if phase is None else check_number(phase, where, "phase", found, "angle", "rad")
        self._problems.extend(found)
        if not found:
            self._laws[link] = InputLaw(ratio, phase)
        return self

    def assembly(
        self,
        point: str,
        *,
        left_of: tuple[str, str] | None = None,
        right_of: tuple[str, str] | None = None,
        towards: float | None = None,
        origin: str | None = None,
        branch: int | None = None,
        mode: str = "keep",
        phi: float | None = None,
    ) -> "MechanismBuilder":
        """Pick the assembly branch of the group that places ``point``.

        Exactly one of: ``left_of=(X, Y)`` / ``right_of=(X, Y)`` (the point lies left / right of
        the directed line X -> Y); ``towards=angle`` with ``origin=X`` (the point lies from X in
        that direction, rad); ``branch=+1/-1`` (the solver's raw sign, see its kind).
        ``mode``: ``"keep"`` (default) keeps that branch through change points, ``"follow"``
        follows the motion continuously through them (see :class:`Assembly`). ``phi`` (rad):
        the input angle at which the condition holds (default: at most angles of a turn).
        """
        where = f"assembly of point '{point}'"
        if mode not in ("keep", "follow"):
            self._problems.append(f"{where}: mode must be 'keep' or 'follow', got {mode!r}")
            return self
        if phi is not None and not (_is_number(phi) and math.isfinite(phi)):
            self._problems.append(f"{where}: the input angle of the condition must be a finite number, "
                                  f"got {phi!r}")
            return self
        extra = {"mode": mode, "phi": None if phi is None else float(phi)}
        given = [k for k, v in (("left_of", left_of), ("right_of", right_of), ("towards", towards),
                                ("branch", branch)) if v is not None]
        if len(given) != 1:
            self._problems.append(
                f"{where}: give exactly one of left_of, right_of, towards(_deg), branch; got {given}")
            return self
        if left_of is not None or right_of is not None:
            refs = left_of if left_of is not None else right_of
            if not (isinstance(refs, (list, tuple)) and len(refs) == 2):
                self._problems.append(f"{where}: {given[0]} must name two points, got {refs!r}")
                return self
            self._assembly.append(Assembly(point, given[0], tuple(refs), **extra))
        elif towards is not None:
            if origin is None or not _is_number(towards):
                self._problems.append(f"{where}: 'towards' needs an angle and 'from' a point")
                return self
            self._assembly.append(Assembly(point, "towards", (origin,), float(towards), **extra))
        else:
            if branch not in (1, -1):
                self._problems.append(f"{where}: branch must be +1 or -1, got {branch!r}")
                return self
            self._assembly.append(Assembly(point, "branch", value=int(branch), **extra))
        return self

    def output(self, quantity: str, start: str = "max") -> "MechanismBuilder":
        """Declare the output coordinate (``"B.x"``, ``"3.theta"``, ``"K.s"``) and its start."""
        self._output = Output(quantity, start)
        return self

    def input_range(self, start: float, end: float, *, degrees: bool = False,
                    given: str | None = None) -> "MechanismBuilder":
        """Analyse the mechanism over the first input's coordinate from ``start`` to ``end``
        instead of a full turn: angles (rad) for an input that does not turn fully (a rocker
        input, a tangent mechanism; a span of more than 0 and less than a turn), or the stroke (m)
        of a slide input (which needs one).

        Tables run from ``start`` to ``end`` (``end < start`` for an input that turns clockwise or
        slides backwards). ``degrees``: the range was given in degrees (converted to rad), which
        only an input angle accepts; ``given``: how it was written (named in messages).
        """
        ok = [check_number(v, "input range", name, self._problems, "real") for v, name in
              ((start, "start"), (end, "end"))]
        if None not in ok:
            self._range = (ok[0], ok[1])
            self._range_in_degrees = degrees
            self._range_given = given
        return self

    def build(self, **extra: Any) -> Mechanism:
        """Validate and return the mechanism; raise :class:`SchemeError` listing every problem."""
        if self.frame not in self._links:
            self._links[self.frame] = Link(self.frame)
        mech = Mechanism(
            self.name,
            dict(self._links),
            dict(self._pairs),
            tuple(self._inputs),
            self.frame,
            tuple(sorted(self._assembly, key=lambda a: a.point)),
            self._output,
            self.description,
            dict(extra),
            self._range,
            dict(self._laws),
        )
        refused = dict(self._unplaced)
        for name in self._incomplete:
            refused[name] = _EVERY_NAME
        problems = self._problems + validate(mech, self._rejected, refused, inputs_refused=self._inputs_refused)
        if self._range_in_degrees and mech.inputs and not mech.coordinate.is_angle:
            problems.append(f"range_deg: input '{mech.inputs[0]}' is a slide, whose stroke is in m: give "
                            "range = [s_start, s_end] (m) instead")
        elif not self._inputs_refused:
            problems.extend(_range_problems(mech, self._range_given or "input range"))
        for link, keys in self._law_degrees.items():
            if link in mech.inputs and mech.input_kind(link) == "slide":
                problems.append(f"input_laws.{link}: {', '.join(keys)}: input '{link}' is a slide, whose coordinate "
                                "is in m: give ratio and phase (m)")
        if problems:
            raise SchemeError(problems)
        return mech


class _EveryName:
    """The points of a link whose declaration left them unknown: contains every name."""

    def __contains__(self, name) -> bool:
        return True

    def __iter__(self):
        return iter(())


_EVERY_NAME = _EveryName()


def validate(mech: Mechanism, rejected=frozenset(), unplaced: Mapping[str, set] | None = None, *,
             inputs_refused: bool = False) -> list[str]:
    """Every problem of a mechanism's declaration (empty when it is sound).

    Parameters
    ----------
    mech : Mechanism
    rejected : set of str
        Links and pairs whose declarations were refused (already reported): problems that only
        follow from their absence are left out.
    unplaced : dict of link -> set of str
        Points and guides of a link whose declarations were refused (already reported).
    inputs_refused : bool
        The declaration of the input links was refused (already reported).
    """
    p: list[str] = []
    links = mech.links
    unplaced = unplaced or {}

    def refused(link: str, name: str) -> bool:
        return link in rejected or name in unplaced.get(link, ())

    for pair in mech.pairs.values():
        where = f"pair '{pair.name}'"
        a, b = pair.links
        bad = [x for x in (a, b) if x not in links]
        for x in bad:
            if x not in rejected:
                p.append(f"{where}: joins unknown link '{x}'")
        if bad:
            continue
        if a == b:
            p.append(f"{where}: joins link '{a}' to itself")
            continue
        if isinstance(pair, Revolute):
            for x in (a, b):
                if pair.point not in links[x].points and not refused(x, pair.point):
                    p.append(f"{where}: point '{pair.point}' is not declared on link '{x}'")
        elif (pair.guide not in links[a].guides and pair.point not in links[b].points
              and pair.guide in links[b].guides and pair.point in links[a].points):
            p.append(f"{where}: links {list(pair.links)} are in the wrong order: a prismatic pair's links "
                     f"are [guide link, slider link], and guide '{pair.guide}' is on link '{b}'")
        else:
            if pair.guide not in links[a].guides and not refused(a, pair.guide):
                p.append(f"{where}: link '{a}' has no guide '{pair.guide}' "
                         f"(it has {sorted(links[a].guides) or 'none'})")
            if pair.point not in links[b].points and not refused(b, pair.point):
                p.append(f"{where}: point '{pair.point}' is not declared on slider link '{b}'")
    clash = sorted(set(mech.pairs) & set(links))
    for name in clash:
        p.append(f"name '{name}' is used for both a link and a pair")
    if not mech.inputs and not inputs_refused:
        p.append("no input link declared (input = \"<link>\")")
    if len(set(mech.inputs)) != len(mech.inputs):
        p.append(f"input links declared twice: {list(mech.inputs)}")
    for name in mech.inputs:
        p.extend(_input_problems(mech, name, rejected))
    p.extend(_law_problems(mech))
    known_points = {q for lk in links.values() for q in lk.points}
    refused_points = {q for names in unplaced.values() for q in names}
    for rule in mech.assembly:
        for q in (rule.point, *rule.refs):
            if not isinstance(q, str) or (q not in known_points and q not in refused_points):
                p.append(f"assembly of point '{rule.point}': unknown point '{q}'")
    if mech.output is not None:
        p.extend(_output_problems(mech, refused=set(rejected) | refused_points))
    return p


def _input_problems(mech: Mechanism, name: str, rejected=frozenset()) -> list[str]:
    """Problems of one declared input: a link pinned to the frame or in a prismatic pair with it,
    or a pair (a revolute pair with the frame, or any prismatic pair)."""
    if name in mech.pairs:
        pair = mech.pairs[name]
        if isinstance(pair, Revolute) and mech.frame not in pair.links:
            return [f"input pair '{name}' is a revolute pair between two moving links {list(pair.links)}: an input "
                    "pair is a revolute pair with the frame (a crank) or a prismatic pair (a slide)"]
        return []
    if name not in mech.links:
        return [] if name in rejected else [f"input link '{name}' is not a declared link (nor a pair)"]
    if name == mech.frame:
        return [f"input link '{name}' is the frame"]
    if not rejected and mech.input_pair(name) is None:
        return [f"input link '{name}' is not pinned to the frame '{mech.frame}' by a revolute pair nor slides on it "
                "by a prismatic pair"]
    return []


def _range_problems(mech: Mechanism, given: str = "input range") -> list[str]:
    """Problems of the input range for the first input's coordinate: an angle's range spans more
    than 0 and less than a turn; a slide needs a stroke of nonzero length."""
    if not mech.inputs:
        return []
    span = mech.input_range
    first = mech.inputs[0]
    if mech.coordinate.is_angle:
        if span is not None and not 0 < abs(span[1] - span[0]) < 2 * math.pi:
            a, b = (math.degrees(v) for v in span)
            return [f"{given}: the range [{a:.10g}, {b:.10g}] deg must span more than 0 and less than 360 deg "
                    f"(a full turn needs no range; choose position 1 with start_deg), got a span of "
                    f"{abs(b - a):.10g} deg"]
        return []
    if span is None:
        return [f"input '{first}' is a slide (prismatic pair '{mech.input_pair(first)}'): declare its stroke, "
                "range = [s_start, s_end] in m (the slide of the pair, as in the table's column "
                f"'{mech.input_pair(first)}.s')"]
    if not span[1] != span[0] or not all(abs(v) <= MAX_MAGNITUDE for v in span):
        return [f"{given}: the stroke [{span[0]:.10g}, {span[1]:.10g}] m of slide input '{first}' must have a "
                f"nonzero length and ends within {MAX_MAGNITUDE:g} m"]
    return []


def _law_problems(mech: Mechanism) -> list[str]:
    """Problems of the input laws: one per further input, none for the first or a link that is no
    input; a table over less than a turn needs an input range inside it."""
    problems = []
    first, further = (mech.inputs[0], mech.inputs[1:]) if mech.inputs else (None, ())
    for link in mech.input_laws:
        if link == first:
            problems.append(f"input law of link '{link}': the first input link's angle is phi itself; "
                            "laws are for the further input links")
        elif link not in further:
            problems.append(f"input law of link '{link}': '{link}' is not an input link (inputs {list(mech.inputs)})")
    for link in further:
        if link not in mech.input_laws:
            problems.append(f"input link '{link}' needs a law (input_laws.{link}: ratio and phase_deg, or table_deg): "
                            f"how its angle follows the first input's ('{first}')")
    for link, law in mech.input_laws.items():
        if law.table is not None and link in further and mech.input_kind(link) == "slide":
            problems.append(f"input law of link '{link}': '{link}' is a slide: give a ratio and a phase (its slide "
                            "= ratio * phi + phase, m), not a table")
            continue
        if law.table is not None and link in further and not mech.coordinate.is_angle:
            problems.append(f"input law of link '{link}': a table law follows the first input's angle, but the "
                            f"first input '{first}' is a slide: give a ratio and a phase (the further input's "
                            "coordinate = ratio * s + phase)")
            continue
        if law.domain is None or link not in further:
            continue
        low, high = law.domain
        span = mech.input_range
        inside = span is not None and low - 1e-9 <= min(span) and max(span) <= high + 1e-9
        if not inside:
            given = "none" if span is None else f"[{math.degrees(span[0]):.10g}, {math.degrees(span[1]):.10g}] deg"
            problems.append(f"input law of link '{link}': its table holds for phi in [{math.degrees(low):.10g}, "
                            f"{math.degrees(high):.10g}] deg only (less than a turn), so the mechanism needs an input "
                            f"range inside it (range_deg); input range: {given}")
    return problems


def _output_problems(mech: Mechanism, refused=frozenset()) -> list[str]:
    """Problems of the declared output; a quantity that names a ``refused`` point, link or pair is
    not reported (its declaration's problem is)."""
    out = mech.output
    where = f"output '{out.quantity}'"
    problems = []
    if out.start not in ("max", "min"):
        problems.append(f"{where}: start must be 'max' or 'min', got {out.start!r}")
    name, _, coord = out.quantity.rpartition(".")
    points = {q for lk in mech.links.values() for q in lk.points}
    ok = (
        (coord in ("x", "y") and name in points)
        or (coord == "theta" and name in mech.links and name != mech.frame)
        or (coord == "s" and isinstance(mech.pairs.get(name), Prismatic))
    )
    if not ok and name not in refused:
        problems.append(f"{where}: expected 'P.x', 'P.y' (point), 'L.theta' (moving link) or "
                        f"'K.s' (prismatic pair)")
    return problems
