"""The mechanism model: links, kinematic pairs and the graph they form.

A :class:`Mechanism` is a graph whose nodes are links (the frame among them) and whose edges are
kinematic pairs. Geometry lives in each link's own frame (docs/methods.md, "Poses and pair
equations"): a link's pose is the global position of its local origin and the angle of its local
x axis.

Build one with :class:`~linkage.model.builder.MechanismBuilder` (the scheme loader uses the same
builder), which validates it. A mechanism is immutable: its mappings (links, pairs, the further
sections ``extra``, the input laws; a link's points and guides) are :class:`ReadOnlyMapping`
copies, so a new mechanism comes from :func:`dataclasses.replace`, :meth:`Mechanism.with_extra` or
:meth:`Mechanism.with_input_laws`. Only its :attr:`~Mechanism.cache` of derived results changes.

>>> link = Link("1", points={"O": (0.0, 0.0), "A": (0.1, 0.0)})
>>> link.points["B"] = (0.2, 0.0)
Traceback (most recent call last):
    ...
TypeError: 'ReadOnlyMapping' object does not support item assignment: a mechanism does not change; make a new one (dataclasses.replace, Mechanism.with_extra)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Iterator, Mapping

import networkx as nx

from ..errors import SchemeError
from .input_laws import ANGLE_TOL, InputLaw
from .numbers import Vec

__all__ = [
    "Guide",
    "Link",
    "Revolute",
    "Prismatic",
    "Assembly",
    "Output",
    "Mechanism",
    "InputCoordinate",
    "ReadOnlyMapping",
    "law_problems",
]


class ReadOnlyMapping(Mapping):
    """A mapping that cannot change: the mappings a :class:`Mechanism` and its :class:`Link` hold.

    It keeps its own copy of the items it is made from. Unlike :class:`types.MappingProxyType` it
    pickles (mechanisms go to worker processes when variants run in parallel). Equal to any mapping
    with the same items; hashable when its values are. Only the mapping itself is read-only: the
    values are what was given (tuples, frozen dataclasses, or the raw tables of a scheme's further
    sections in ``Mechanism.extra``).

    >>> laws = ReadOnlyMapping({"2": 1.0})
    >>> laws == {"2": 1.0}, "2" in laws, len(laws)
    (True, True, 1)
    >>> del laws["2"]
    Traceback (most recent call last):
        ...
    TypeError: 'ReadOnlyMapping' object does not support item deletion: a mechanism does not change; make a new one (dataclasses.replace, Mechanism.with_extra)
    """

    __slots__ = ("_items",)
    _HINT = "a mechanism does not change; make a new one (dataclasses.replace, Mechanism.with_extra)"

    def __init__(self, items: Mapping[str, Any] | Any = ()):
        object.__setattr__(self, "_items", dict(items))

    @classmethod
    def of(cls, items: Mapping[str, Any]) -> "ReadOnlyMapping":
        """``items`` itself when it is read-only already, else a read-only copy."""
        return items if isinstance(items, cls) else cls(items)

    def __getitem__(self, key):
        return self._items[key]

    def __iter__(self) -> Iterator:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __contains__(self, key) -> bool:
        return key in self._items

    def get(self, key, default=None):
        return self._items.get(key, default)

    def keys(self):
        return self._items.keys()

    def items(self):
        return self._items.items()

    def values(self):
        return self._items.values()

    def __eq__(self, other) -> bool:
        if isinstance(other, ReadOnlyMapping):
            return self._items == other._items
        if isinstance(other, Mapping):
            return self._items == dict(other.items())
        return NotImplemented

    def __hash__(self) -> int:
        return hash(frozenset(self._items.items()))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._items!r})"

    def __reduce__(self):
        return (type(self), (self._items,))

    def __setitem__(self, key, value):
        raise TypeError(f"'{type(self).__name__}' object does not support item assignment: {self._HINT}")

    def __delitem__(self, key):
        raise TypeError(f"'{type(self).__name__}' object does not support item deletion: {self._HINT}")

    def __setattr__(self, name, value):
        raise AttributeError(f"'{type(self).__name__}' object is read-only: {self._HINT}")

    def __delattr__(self, name):
        raise AttributeError(f"'{type(self).__name__}' object is read-only: {self._HINT}")


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

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", ReadOnlyMapping.of(self.points))
        object.__setattr__(self, "guides", ReadOnlyMapping.of(self.guides))


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
        the SI unit (at most ``limit`` shown); angles folded into [0, 360) deg, whatever turn of a
        longer run they come from."""
        values = list(self.shown(values) % 360.0 if self.is_angle else self.shown(values))
        shown = ", ".join(f"{v:.6g}" for v in values[:limit]) + (" ..." if len(values) > limit else "")
        return f"input {self.kind}(s) ({self.shown_unit}): {shown}"


@dataclass(frozen=True, eq=True)
class Mechanism:
    """A planar mechanism with lower pairs.

    Use :class:`~linkage.model.builder.MechanismBuilder` or :func:`linkage.load` to make one: they
    validate it. ``links``, ``pairs``, ``extra`` and ``input_laws`` are kept as read-only copies
    (:class:`ReadOnlyMapping`; the tables inside ``extra`` are the declaration's raw values).

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

    def __post_init__(self) -> None:
        for name in ("links", "pairs", "extra", "input_laws"):   # read-only copies of what was given
            object.__setattr__(self, name, ReadOnlyMapping.of(getattr(self, name)))

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

    @cached_property
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
        return list(self._point_owners.get(point, ()))

    @cached_property
    def _point_owners(self) -> dict[str, tuple[str, ...]]:
        """Point -> the links declaring it, frame first, then sorted by name (found once)."""
        owners: dict[str, list[str]] = {}
        for name in sorted(self.links):
            for point in self.links[name].points:
                owners.setdefault(point, []).append(name)
        return {p: tuple(sorted(names, key=lambda n: (n != self.frame, n))) for p, names in owners.items()}

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
        problems = [f"mechanism '{self.name}': {p}" for p in law_problems(copy)]
        if problems:
            raise SchemeError(problems)
        return copy


def law_problems(mech: Mechanism) -> list[str]:
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
        inside = span is not None and low - ANGLE_TOL <= min(span) and max(span) <= high + ANGLE_TOL
        if not inside:
            given = "none" if span is None else f"[{math.degrees(span[0]):.10g}, {math.degrees(span[1]):.10g}] deg"
            problems.append(f"input law of link '{link}': its table holds for phi in [{math.degrees(low):.10g}, "
                            f"{math.degrees(high):.10g}] deg only (less than a turn), so the mechanism needs an input "
                            f"range inside it (range_deg); input range: {given}")
    return problems
