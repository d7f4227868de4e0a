"""The drawing model of a course project's sheets: primitives on paper, in millimetres.

A sheet is a :class:`Drawing`: a paper size (A1 841 x 594 mm ...), a list of primitives --
:class:`Line` (open or closed polylines), :class:`Circle`, :class:`Arrow`, :class:`Text` -- each
on a named layer (:data:`LAYERS`), the named rectangular :class:`Region` each part of the sheet
was given (for the layout checks: nothing outside the frame, nothing over the title block), and
the scales it uses (:class:`Scale`, ``μ_l = 0.002 m/mm``). Coordinates are millimetres of paper
from the lower-left corner, y up. The writers (:mod:`~.writers`) turn one drawing into PDF, SVG
and DXF, so every format shows the same geometry.

A :class:`View` maps a quantity's own coordinates (metres of the mechanism, m/s of a plan,
newtons of a polygon, or the two axes of a diagram) to paper through a scale, so a composer
draws in physical units and the scale is stated once.

>>> d = Drawing("A3")
>>> d.size
(420.0, 297.0)
>>> v = d.view(Scale("μ_l", 0.002, "m/mm"), origin=(100.0, 100.0))
>>> v.paper((0.1, 0.0))
(150.0, 100.0)
>>> standard_scale(0.37, 60, 120)      # 0.37 m to between 60 and 120 mm: 0.004 m/mm gives 92.5 mm
0.004
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

__all__ = ["PAPERS", "LAYERS", "STANDARD_MANTISSAS", "Scale", "Line", "Circle", "Arrow", "Text", "Region", "View",
           "Drawing", "standard_scale"]

#: paper sizes, landscape (width, height), mm
PAPERS = {"A1": (841.0, 594.0), "A2": (594.0, 420.0), "A3": (420.0, 297.0), "A4": (297.0, 210.0)}
#: the layers every primitive is on (DXF layers; PDF/SVG line styles by layer)
LAYERS = ("frame", "outline", "links", "positions", "trajectories", "plans", "forces", "diagrams", "dimensions",
          "text")
#: the mantissas of the standard drawing scales: 1, 2, 2.5, 4, 5 x 10^n
STANDARD_MANTISSAS = (1.0, 2.0, 2.5, 4.0, 5.0)


def standard_scale(longest: float, low_mm: float = 60.0, high_mm: float = 120.0) -> float:
    """The standard scale (1, 2, 2.5, 4, 5 x 10^n units per mm) that draws ``longest`` (> 0, in
    the quantity's unit) between ``low_mm`` and ``high_mm`` of paper: the largest such drawing,
    else the one closest to that range. Raises ValueError for a length that is not positive and
    finite."""
    if not (math.isfinite(longest) and longest > 0):
        raise ValueError(f"a scale needs a positive finite length to draw, got {longest!r}")
    exponent = math.floor(math.log10(longest / high_mm))
    candidates = sorted(m * 10.0 ** e for e in (exponent - 1, exponent, exponent + 1) for m in STANDARD_MANTISSAS)
    inside = [s for s in candidates if low_mm <= longest / s <= high_mm]
    if inside:
        return float(_tidy(min(inside)))
    return float(_tidy(min(candidates, key=lambda s: min(abs(longest / s - low_mm), abs(longest / s - high_mm)))))


def _tidy(value: float) -> float:
    """``value`` rounded to 12 significant digits (0.1 * 4 is 0.4, not 0.4000000000000001)."""
    return float(f"{value:.12g}")


@dataclass(frozen=True)
class Scale:
    """A drawing scale: ``value`` units of the quantity per mm of paper (``μ_v = 0.02 (m/s)/mm``)."""

    symbol: str
    value: float
    unit: str

    def __str__(self) -> str:
        return f"{self.symbol} = {self.value:g} {self.unit}"


@dataclass(frozen=True)
class Line:
    """A polyline through ``points`` ``(n, 2)`` mm; ``closed`` joins the last point to the first."""

    points: tuple[tuple[float, float], ...]
    layer: str = "outline"
    width: float = 0.35          # mm
    dashed: bool = False
    closed: bool = False


@dataclass(frozen=True)
class Circle:
    centre: tuple[float, float]
    radius: float                # mm
    layer: str = "outline"
    width: float = 0.35
    filled: bool = False


@dataclass(frozen=True)
class Arrow:
    """A vector from ``start`` to ``end`` (mm) with a head of length ``head`` mm at ``end``."""

    start: tuple[float, float]
    end: tuple[float, float]
    layer: str = "plans"
    width: float = 0.5
    head: float = 4.0

    @property
    def length(self) -> float:
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])


@dataclass(frozen=True)
class Text:
    """``text`` at ``at`` (mm), ``height`` mm (capital letters), turned ``angle`` degrees CCW;
    ``anchor``: horizontal ("left", "center", "right") and vertical ("bottom", "middle", "top")."""

    at: tuple[float, float]
    text: str
    height: float = 3.5
    layer: str = "text"
    anchor: tuple[str, str] = ("left", "bottom")
    angle: float = 0.0

    def box(self) -> tuple[float, float, float, float]:
        """Approximate extent ``(x0, y0, x1, y1)`` mm (width 0.7 of the height per character;
        unturned text)."""
        width = 0.7 * self.height * max(len(line) for line in self.text.split("\n"))
        lines = self.text.count("\n") + 1
        tall = self.height * (1.6 * lines - 0.6)
        x0 = self.at[0] - {"left": 0.0, "center": width / 2, "right": width}[self.anchor[0]]
        y0 = self.at[1] - {"bottom": 0.0, "middle": tall / 2, "top": tall}[self.anchor[1]]
        return (x0, y0, x0 + width, y0 + tall)


@dataclass(frozen=True)
class Region:
    """A named part of the sheet, ``box = (x0, y0, x1, y1)`` mm, with what it holds."""

    name: str
    box: tuple[float, float, float, float]


Primitive = Line | Circle | Arrow | Text


@dataclass
class View:
    """Draws a quantity's coordinates on a drawing at a scale: a point ``q`` (in the quantity's
    unit) goes to ``origin + (q - at) / scale.value`` mm (``scale_y`` for the second axis of a
    diagram, when given)."""

    drawing: "Drawing"
    scale: Scale
    origin: tuple[float, float]
    at: tuple[float, float] = (0.0, 0.0)
    scale_y: Scale | None = None

    def paper(self, q) -> tuple[float, float]:
        """Paper position (mm) of the point ``q`` ``(2,)``."""
        sy = self.scale.value if self.scale_y is None else self.scale_y.value
        return (round(self.origin[0] + (float(q[0]) - self.at[0]) / self.scale.value, 9),
                round(self.origin[1] + (float(q[1]) - self.at[1]) / sy, 9))

    def papers(self, points) -> tuple[tuple[float, float], ...]:
        return tuple(self.paper(p) for p in np.asarray(points, float).reshape(-1, 2))

    def line(self, points, **style) -> Line:
        return self.drawing.add(Line(self.papers(points), **style))

    def circle(self, centre, radius_mm: float, **style) -> Circle:
        return self.drawing.add(Circle(self.paper(centre), radius_mm, **style))

    def arrow(self, start, end, **style) -> Arrow:
        return self.drawing.add(Arrow(self.paper(start), self.paper(end), **style))

    def text(self, at, text: str, offset=(0.0, 0.0), **style) -> Text:
        x, y = self.paper(at)
        return self.drawing.add(Text((x + offset[0], y + offset[1]), text, **style))


@dataclass
class Drawing:
    """One sheet: its paper, primitives, regions and scales (see the module docstring)."""

    paper: str = "A1"
    items: list = field(default_factory=list)
    regions: list[Region] = field(default_factory=list)
    scales: dict[str, Scale] = field(default_factory=dict)
    title: str = ""

    def __post_init__(self) -> None:
        if self.paper not in PAPERS:
            raise ValueError(f"paper must be one of {', '.join(PAPERS)}, got {self.paper!r}")

    @property
    def size(self) -> tuple[float, float]:
        return PAPERS[self.paper]

    def add(self, item):
        layer = getattr(item, "layer", None)
        if layer not in LAYERS:
            raise ValueError(f"unknown layer {layer!r} (one of {', '.join(LAYERS)})")
        self.items.append(item)
        return item

    def region(self, name: str, box: Sequence[float]) -> Region:
        """Reserve the part ``box = (x0, y0, x1, y1)`` mm of the sheet for ``name``."""
        r = Region(name, tuple(float(v) for v in box))
        self.regions.append(r)
        return r

    def use(self, scale: Scale) -> Scale:
        """Record a scale the sheet states (one per symbol: a second, different one is an error)."""
        known = self.scales.get(scale.symbol)
        if known is not None and known != scale:
            raise ValueError(f"the sheet already draws {known} and cannot also use {scale}")
        self.scales[scale.symbol] = scale
        return scale

    def view(self, scale: Scale, origin=(0.0, 0.0), at=(0.0, 0.0), scale_y: Scale | None = None) -> View:
        """A :class:`View` at ``scale`` (and ``scale_y``), recorded in the sheet's scales."""
        self.use(scale)
        if scale_y is not None:
            self.use(scale_y)
        return View(self, scale, tuple(origin), tuple(at), scale_y)

    def bounds(self, item) -> tuple[float, float, float, float]:
        """Extent ``(x0, y0, x1, y1)`` mm of a primitive (texts approximately)."""
        if isinstance(item, Text):
            return item.box()
        if isinstance(item, Circle):
            (x, y), r = item.centre, item.radius
            return (x - r, y - r, x + r, y + r)
        pts = np.array(item.points if isinstance(item, Line) else (item.start, item.end), float)
        return (float(pts[:, 0].min()), float(pts[:, 1].min()), float(pts[:, 0].max()), float(pts[:, 1].max()))
