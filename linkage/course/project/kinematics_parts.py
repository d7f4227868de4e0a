"""The pieces of the kinematics sheet drawn on paper (mm): the mechanism's scenes, labels placed
clear of each other, a plan of velocities or accelerations, a diagram over the turned angle.

Used by :mod:`~.kinematics_sheet`, which lays them out on the sheet. Every piece draws into a
:class:`~.model.Drawing` inside a box ``(x0, y0, x1, y1)`` mm it is given; quantities go to paper
through a :class:`~.model.View` at a stated scale (the structural diagram alone is a sketch
without a scale, through :class:`Sketch`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ...kinetostatics.plans import POLE, Plan
from ...report.drawing import Scene, rail_hatch, support
from .frame import WIDTH_MARGIN
from ...report.plan_drawings import nice_scale
from .model import Arrow, Circle, Drawing, Line, Text

__all__ = ["Sketch", "fitting_scale", "LabelPlacer", "draw_scene", "scene_points", "plan_extent",
           "draw_plan", "draw_diagram", "image_name", "vector_name", "SUBSCRIPT"]

#: digits as subscripts (DejaVu Sans has them; so does every CAD font used for DXF text)
SUBSCRIPT = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
#: the clear gap a placed label keeps from the lines near it, mm
CLEAR = 0.6


def fitting_scale(span: float, room_mm: float) -> float:
    """The smallest students' scale (1, 2, 2.5, 4, 5 x 10^n units per mm) that draws ``span``
    (> 0) within ``room_mm`` mm: the largest drawing that fits (1.0 for a span that is not
    positive and finite)."""
    return nice_scale(span / room_mm) if math.isfinite(span) and span > 0 else 1.0


@dataclass
class Sketch:
    """A drawing without a stated scale (the structural diagram): ``origin + (q - at) * factor`` mm."""

    origin: tuple[float, float]
    at: tuple[float, float]
    factor: float          # mm per m

    def paper(self, q) -> tuple[float, float]:
        return (round(self.origin[0] + (float(q[0]) - self.at[0]) * self.factor, 9),
                round(self.origin[1] + (float(q[1]) - self.at[1]) * self.factor, 9))

    def papers(self, points) -> tuple[tuple[float, float], ...]:
        return tuple(self.paper(p) for p in np.asarray(points, float).reshape(-1, 2))


def _to_paper(view) -> Callable:
    """The point mapping of a :class:`~.model.View` or a :class:`Sketch`."""
    return view.paper


# ----------------------------------------------------------------------------------------------
# labels clear of each other
# ----------------------------------------------------------------------------------------------


class LabelPlacer:
    """Puts texts near points where they overlap no text already on the drawing (nor the marks
    given with :meth:`avoid`), inside a box; a text that finds no free place is not drawn and
    :meth:`place` returns None."""

    def __init__(self, drawing: Drawing, box: Sequence[float]):
        self.drawing, self.box = drawing, tuple(box)
        self.taken = [t.box() for t in drawing.items if isinstance(t, Text)]
        self.marks = np.zeros((0, 2))

    def avoid_lines(self) -> None:
        """Keep the texts off the lines, circles and arrows already drawn inside the box (points
        along them every 0.5 mm)."""
        x0, y0, x1, y1 = self.box
        pts = []
        for item in self.drawing.items:
            if isinstance(item, Line):
                seq = list(item.points) + ([item.points[0]] if item.closed else [])
            elif isinstance(item, Arrow):
                seq = [item.start, item.end]
            elif isinstance(item, Circle):
                seq = [(item.centre[0] + item.radius * math.cos(a), item.centre[1] + item.radius * math.sin(a))
                       for a in np.linspace(0, 2 * math.pi, 9)]
            else:
                continue
            arr = np.asarray(seq, float)
            if not (arr[:, 0].max() >= x0 and arr[:, 0].min() <= x1 and arr[:, 1].max() >= y0
                    and arr[:, 1].min() <= y1):
                continue
            for a, b in zip(arr[:-1], arr[1:]):
                k = max(2, int(np.hypot(*(b - a)) / 0.5) + 1)
                pts.append(a + np.linspace(0.0, 1.0, k)[:, None] * (b - a))
        if pts:
            self.marks = np.vstack([self.marks, *pts])

    def avoid(self, box: Sequence[float]) -> None:
        self.taken.append(tuple(box))

    def free(self, b, clear: float = CLEAR) -> bool:
        """Whether the box ``b = (x0, y0, x1, y1)`` mm lies in the placer's box, off the texts
        taken and ``clear`` mm or more off the marks (the box widened to the width DejaVu Sans
        draws, :data:`~.frame.WIDTH_MARGIN`)."""
        x0, y0, x1, y1 = self.box
        if b[0] < x0 or b[1] < y0 or b[2] > x1 or b[3] > y1:
            return False
        if any(b[0] < t[2] and t[0] < b[2] and b[1] < t[3] and t[1] < b[3] for t in self.taken):
            return False
        grow = (b[2] - b[0]) * (WIDTH_MARGIN - 1) / 2 + clear
        m = self.marks
        return not np.any((m[:, 0] > b[0] - grow) & (m[:, 0] < b[2] + grow) & (m[:, 1] > b[1] - clear)
                          & (m[:, 1] < b[3] + clear))

    _free = free

    def place(self, at: Sequence[float], text: str, height: float, rings: Sequence[float] = (1.2, 2.5, 4.5, 7.0),
              prefer: Sequence[float] | None = None, layer: str = "text") -> Text | None:
        """The text near ``at`` (mm): tried at the ``rings`` distances (in text heights) in eight
        directions, ``prefer`` (a unit vector) first."""
        dirs = [(math.cos(a), math.sin(a)) for a in np.radians([45, 135, -45, -135, 0, 90, 180, -90])]
        if prefer is not None and np.hypot(*prefer) > 0:
            p = np.asarray(prefer, float) / np.hypot(*prefer)
            dirs.sort(key=lambda d: -(d[0] * p[0] + d[1] * p[1]))
        for ring in rings:
            for dx, dy in dirs:
                ha = "left" if dx > 0.3 else "right" if dx < -0.3 else "center"
                va = "bottom" if dy > 0.3 else "top" if dy < -0.3 else "middle"
                item = Text((at[0] + dx * ring * height, at[1] + dy * ring * height), text, height=height,
                            layer=layer, anchor=(ha, va))
                b = item.box()
                if self._free(b):
                    self.taken.append(b)
                    return self.drawing.add(item)
        return None

    def put(self, item: Text) -> Text:
        """A text at a place chosen by the caller (recorded as taken)."""
        self.taken.append(item.box())
        return self.drawing.add(item)


# ----------------------------------------------------------------------------------------------
# the mechanism
# ----------------------------------------------------------------------------------------------


def _rect(centre, angle: float, length: float, height: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    along, across = np.array([c, s]), np.array([-s, c])
    return np.array([centre + a * length / 2 * along + b * height / 2 * across
                     for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def draw_scene(drawing: Drawing, scene: Scene, view, unit: float, *, layer: str, width: float,
               frame: bool = True, pin_mm: float = 1.0) -> list[tuple[str, tuple[float, float]]]:
    """One position of the mechanism: links (lines, polygons), sliders (blocks), slots, and with
    ``frame`` the frame's guides and pivots' supports; revolute pairs as circles of ``pin_mm``.
    ``unit`` (m) sizes the blocks and supports as the report's scenes do. Returns the revolute
    pairs drawn: (pair name, paper point)."""
    paper = _to_paper(view)
    papers = lambda pts: tuple(paper(p) for p in np.asarray(pts, float).reshape(-1, 2))  # noqa: E731
    for _, poly in scene.bodies:
        pts = papers(poly)
        drawing.add(Line(pts, layer=layer, width=width, closed=len(pts) >= 3))
    for _, line in scene.slots:
        drawing.add(Line(papers(line), layer=layer, width=width))
    for _, centre, angle, on_frame in scene.blocks:
        size = (3.0 * unit, 1.4 * unit) if on_frame else (2.0 * unit, 1.1 * unit)
        drawing.add(Line(papers(_rect(centre, angle, *size)), layer=layer, width=width, closed=True))
    if frame:
        for line, side in scene.rails:
            surface, strokes = rail_hatch(line, side, unit)
            drawing.add(Line(papers(surface), layer="outline", width=0.5))
            for a, b in strokes:
                drawing.add(Line(papers([a, b]), layer="outline", width=0.18))
        for p, direction in scene.pivots:
            triangle, ground, strokes = support(p, direction, unit)
            drawing.add(Line(papers(triangle), layer="outline", width=0.35, closed=True))
            drawing.add(Line(papers(ground), layer="outline", width=0.5))
            for a, b in strokes:
                drawing.add(Line(papers([a, b]), layer="outline", width=0.18))
    pins = []
    for name, p in scene.pins:
        drawing.add(Circle(paper(p), pin_mm, layer=layer, width=min(width, 0.35)))
        pins.append((name, paper(p)))
    return pins


def scene_points(scene: Scene, unit: float) -> np.ndarray:
    """``(M, 2)`` m: every point a scene draws (links, blocks, guides, supports, trajectories),
    for its extent."""
    pts = [np.asarray(p, float) for p in scene.points.values()]
    pts += [q for _, poly in scene.bodies for q in poly] + [q for _, line in scene.slots for q in line]
    for _, centre, angle, on_frame in scene.blocks:
        pts += list(_rect(centre, angle, *((3.0 * unit, 1.4 * unit) if on_frame else (2.0 * unit, 1.1 * unit))))
    for line, side in scene.rails:
        surface, strokes = rail_hatch(line, side, unit)
        pts += list(line) + list(surface) + list(strokes.reshape(-1, 2))
    for p, direction in scene.pivots:
        tri, ground, strokes = support(p, direction, unit)
        pts += list(tri) + list(ground) + list(strokes.reshape(-1, 2))
    for _, _, curve in scene.trajectories:
        pts += list(curve)
    out = np.array(pts, float).reshape(-1, 2)
    return out[np.all(np.isfinite(out), axis=1)]


# ----------------------------------------------------------------------------------------------
# plans
# ----------------------------------------------------------------------------------------------


def _split(label: str) -> tuple[str, str]:
    """``S2`` -> (S, 2), ``A(3)`` -> (A, 3), ``O1(3)`` -> (O, 1,3)."""
    m = re.fullmatch(r"([A-Za-z]+)(\d*)(?:\(([^)]+)\))?", label)
    if not m:
        return label, ""
    letters, digits, link = m.groups()
    return letters, ",".join(x for x in (digits, link) if x)


def _plain(label: str) -> str:
    """A point's name as on paper: ``S2`` -> S₂, ``A(3)`` -> A₃ (other subscripts after ``_``)."""
    head, sub = _split(label)
    if not sub:
        return head
    return head + (sub.translate(SUBSCRIPT) if sub.isdigit() else "_" + sub)


def image_name(label: str, pole: str) -> str:
    """The image of a point in lower case, as the plans' drawings letter it: ``B`` -> b,
    ``A(3)`` -> a₃, ``S2`` -> s₂, the pole ``p`` or ``π``; the end of a normal part ``n(B,A)``
    -> n_BA, of a Coriolis part ``k(A,3)`` -> k_A."""
    if label == POLE:
        return pole
    m = re.fullmatch(r"([nk])\((.+),(.+)\)", label)
    if m:
        kind, a, b = m.groups()
        return f"n_{_plain(a)}{_plain(b)}" if kind == "n" else f"k_{_plain(a)}"
    letters = re.match(r"[A-Za-z]*", label).group(0)
    return _plain(letters.lower() + label[len(letters):])


def vector_name(v, quantity: str) -> str:
    """``v_B``, ``v_BA``, ``a^n_BA``, ``a^τ_BA``, ``a^k_AA₃``, ``a^r_AA₃`` (plain text)."""
    s = "v" if quantity == "velocity" else "a"
    if v.kind == "absolute":
        return f"{s}_{_plain(v.point)}"
    top = {"normal": "^n", "tangential": "^τ", "coriolis": "^k"}.get(v.kind, "")
    if v.kind == "relative-slide" and quantity == "acceleration":
        top = "^r"
    return f"{s}{top}_{_plain(v.point)}{_plain(v.about)}"


def drawn_vectors(plan: Plan) -> list:
    """The vectors a plan draws: those of the construction (not the similarity ones)."""
    return [v for v in plan.vectors if v.role != "similarity"]


def plan_extent(plan: Plan, i: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Lower-left and upper-right corners of a plan's images and the pole (quantity units), and
    its longest drawn vector, at row ``i``."""
    pts = [np.zeros(2)] + [np.asarray(img[i], float) for img in plan.images.values()]
    pts = np.array([p for p in pts if np.all(np.isfinite(p))])
    longest = max([float(np.hypot(*v.vector[i])) for v in drawn_vectors(plan)] + [0.0])
    return pts.min(axis=0), pts.max(axis=0), longest


def draw_plan(drawing: Drawing, plan: Plan, i: int, view, pole: str, height: float, box,
              shortest_mm: float = 0.3) -> dict[str, tuple[float, float]]:
    """A plan at row ``i`` through ``view`` (its scale): absolute vectors from the pole, relative
    vectors (and the parts of relative accelerations) from their images, the figure of each link
    as a thin outline, and the images lettered in lower case. Returns image label -> paper point."""
    at = {label: view.paper(img[i]) for label, img in plan.images.items() if np.all(np.isfinite(img[i]))}
    at[POLE] = view.paper((0.0, 0.0))
    for labels in plan.links.values():              # a link's figure, similar to the link
        pts = [at[q] for q in labels if q in at]
        if len(pts) >= 3:
            drawing.add(Line(tuple(pts), layer="plans", width=0.18, closed=True))
    for v in drawn_vectors(plan):
        start = np.asarray(at[v.start])
        end = start + np.asarray(v.vector[i], float) / view.scale.value
        if np.hypot(*(end - start)) < shortest_mm:
            continue
        if v.kind == "relative" and plan.quantity == "acceleration":    # the sum of its two parts
            drawing.add(Line((tuple(start), tuple(end)), layer="plans", width=0.25, dashed=True))
            continue
        drawing.add(Arrow(tuple(start), tuple(end), layer="plans", width=0.5 if v.kind == "absolute" else 0.35,
                          head=min(3.0, 0.3 * float(np.hypot(*(end - start))))))
    placer = LabelPlacer(drawing, box)
    centre = np.mean(np.array(list(at.values())), axis=0)
    shown: list[tuple[tuple[float, float], list[str]]] = []
    for label, xy in at.items():                    # images that coincide share one label
        for place, names in shown:
            if math.dist(place, xy) < 0.6:
                names.append(label)
                break
        else:
            shown.append((xy, [label]))
    for xy, names in sorted(shown, key=lambda s: POLE not in s[1]):
        names.sort(key=lambda q: (q != POLE, q))
        text = ", ".join(image_name(q, pole) for q in names)
        drawing.add(Circle(xy, 0.5, layer="plans", width=0.25, filled=True))
        placer.place(xy, text, height, prefer=np.asarray(xy) - centre, rings=(0.6, 1.2, 2.2, 3.5, 5.0))
    return at


# ----------------------------------------------------------------------------------------------
# diagrams over the turned angle
# ----------------------------------------------------------------------------------------------


def draw_diagram(drawing: Drawing, view, x: np.ndarray, y: np.ndarray, *, x_label: str, y_label: str,
                 title: str, height: float, ticks: Sequence[tuple[float, str]] = (), width: float = 1e9,
                 small: float = 2.5) -> None:
    """A curve ``y(x)`` through ``view`` (both scales) with its axes from the origin of ``view``
    (x from its smallest to largest value, y over the curve's range and 0), the axes' names (with
    units), value ticks numbered on the y axis, the table positions' ticks ``(x, label)`` numbered
    on the x axis on the side the curve leaves free, and the title above (lines at most ``width``
    mm, text ``height`` mm; the numbers ``small`` mm)."""
    ok = np.isfinite(x) & np.isfinite(y)
    xs, ys = x[ok], y[ok]
    lo, hi = min(float(ys.min()), 0.0), max(float(ys.max()), 0.0)
    (ax0, ay_lo), (ax1, ay_hi) = view.paper((float(xs.min()), lo)), view.paper((float(xs.max()), hi))
    _, y0 = view.paper((0.0, 0.0))
    x_end = ax1 + 6.0
    top = ay_hi + 6.0
    drawing.add(Line(((ax0, y0), (x_end, y0)), layer="diagrams", width=0.35))
    drawing.add(Line(((ax0, ay_lo - 2.0), (ax0, top)), layer="diagrams", width=0.35))
    drawing.add(Line(((x_end - 2.5, y0 + 0.8), (x_end, y0), (x_end - 2.5, y0 - 0.8)), layer="diagrams", width=0.35))
    drawing.add(Line(((ax0 - 0.8, top - 2.5), (ax0, top), (ax0 + 0.8, top - 2.5)), layer="diagrams", width=0.35))
    segments = np.split(np.arange(len(x)), np.flatnonzero(~ok) + 1)
    curve = []
    for seg in segments:
        seg = seg[ok[seg]]
        if len(seg) >= 2:
            curve.append(view.line(np.column_stack([x[seg], y[seg]]), layer="diagrams", width=0.6))
    drawing.add(Text((x_end + 1.0, y0), x_label, height=height, anchor=("left", "middle")))
    left = ax0 - 3.5 * small - 3.0
    fit = lambda text: min(height, width / (0.7 * WIDTH_MARGIN * max(len(line) for line in text.split("\n"))))  # noqa: E731
    label = drawing.add(Text((left, top + 1.5), y_label, height=fit(y_label), anchor=("left", "bottom")))
    drawing.add(Text((left, label.box()[3] + 0.6 * height), title, height=fit(title), anchor=("left", "bottom")))
    for value in value_ticks(lo, hi, view.scale_y.value if view.scale_y else view.scale.value):
        _, py = view.paper((float(xs.min()), value))
        drawing.add(Line(((ax0 - 1.2, py), (ax0, py)), layer="diagrams", width=0.25))
        if abs(py - y0) > 0.5 * small or value == 0:
            drawing.add(Text((ax0 - 1.8, py), _number(value), height=small, anchor=("right", "middle")))
    pts = np.vstack([ln.points for ln in curve]) if curve else np.zeros((0, 2))
    room = small + 2.2                     # a tick number's height with its gaps, mm
    ends: dict[int, float] = {}            # the right end of the last number above (1) and below (-1)
    for xt, label in ticks:
        px, _ = view.paper((xt, 0.0))
        drawing.add(Line(((px, y0 - 1.0), (px, y0 + 1.0)), layer="diagrams", width=0.25))
        if not label:
            continue
        half = 0.35 * WIDTH_MARGIN * small * len(label) + 0.8
        near = pts[np.abs(pts[:, 0] - px) <= half] if len(pts) else pts
        below = near[(near[:, 1] <= y0) & (near[:, 1] >= y0 - room)] if len(near) else near
        above = near[(near[:, 1] >= y0) & (near[:, 1] <= y0 + room)] if len(near) else near
        if len(below) == 0 or (len(above) and len(below) and
                               np.min(y0 - below[:, 1]) >= np.min(above[:, 1] - y0)):
            side, item = -1, Text((px, y0 - 1.5), label, height=small, anchor=("center", "top"))
        else:
            side, item = 1, Text((px, y0 + 1.5), label, height=small, anchor=("center", "bottom"))
        if px - half < ends.get(side, -np.inf):    # too near the last number on that side: left out
            continue
        ends[side] = px + half
        drawing.add(item)


def value_ticks(lo: float, hi: float, scale: float, spacing_mm: float = 15.0) -> list[float]:
    """Round values (1, 2, 2.5, 5 x 10^n apart, about ``spacing_mm`` or more of paper at
    ``scale`` units per mm) from ``lo`` to ``hi``, 0 among them when it is in the range."""
    if not (hi > lo):
        return [0.0]
    raw = spacing_mm * scale
    exponent = math.floor(math.log10(raw))
    step = next(m * 10.0 ** exponent for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * 10.0 ** exponent >= raw * (1 - 1e-9))
    first = math.ceil(lo / step - 1e-9)
    last = math.floor(hi / step + 1e-9)
    return [float(f"{k * step:.12g}") for k in range(first, last + 1)]


def _number(value: float) -> str:
    """A tick's value, short: 0.05, −1.2, 250 (a minus sign)."""
    text = f"{value:.4g}"
    return text.replace("-", "−") if value else "0"


def spread(desired: Sequence[float], sizes: Sequence[float]) -> np.ndarray:
    """Centres as near ``desired`` (sorted ascending) as they can be with neighbours at least
    the mean of their ``sizes`` apart (labels along a line; least squares per packed run)."""
    desired = np.asarray(desired, float)
    sizes = np.asarray(sizes, float)
    gaps = (sizes[:-1] + sizes[1:]) / 2
    offset = np.concatenate([[0.0], np.cumsum(gaps)])      # packed positions relative to the first
    runs: list[list] = []                                  # [first index, last index, first's centre]
    for i, d in enumerate(desired):
        runs.append([i, i, d])
        while len(runs) > 1:
            a, b = runs[-2], runs[-1]
            if b[2] - (a[2] + offset[b[0]] - offset[a[0]]) >= -1e-9:
                break
            idx = np.arange(a[0], b[1] + 1)
            runs[-2:] = [[a[0], b[1], float(np.mean(desired[idx] - (offset[idx] - offset[a[0]])))]]
    out = np.empty(len(desired))
    for first, last, at in runs:
        idx = np.arange(first, last + 1)
        out[idx] = at + offset[idx] - offset[first]
    return out


def leader(drawing: Drawing, point, box, gap: float = 0.9, least: float = 1.2) -> None:
    """A thin leader from ``point`` (less ``gap`` mm) to the nearest point of the text ``box``,
    when that is more than ``least`` mm away."""
    p = np.asarray(point, float)
    q = np.array([min(max(p[0], box[0]), box[2]), min(max(p[1], box[1]), box[3])])
    d = float(np.hypot(*(q - p)))
    if d <= least:
        return
    u = (q - p) / d
    drawing.add(Line((tuple(p + gap * u), tuple(q - 0.4 * u)), layer="dimensions", width=0.18))


def number_along_path(drawing: Drawing, placer: LabelPlacer, points: dict, sides: dict, height: float,
                      normal: Sequence[float],
                      offsets: Sequence[float] = (1.0, 1.8, 2.6, 3.6, 5.0, 7.0, 9.5, 12.0)) -> dict:
    """Number the points of a path travelled back and forth (a slider's, a rocker's): the
    labels ``{label: (x, y) mm}`` of side +1 in a row along ``normal`` (a unit vector across the
    path), those of side -1 opposite, each row spread along the path so no two touch (:func:`spread`)
    at the least offset (in text heights, ``offsets``) where the whole row is free, a leader from
    each point to its label when they are apart. A label whose row finds no free place is placed
    alone by ``placer``. Returns ``{side: the row's outer edge across the path, mm from the path's
    centre line}``."""
    n = np.asarray(normal, float) / np.hypot(*normal)
    u = np.array([n[1], -n[0]])
    pts = np.array(list(points.values()), float)
    centre = pts.mean(axis=0)
    edges = {}
    for side in (1, -1):
        labels = sorted((lab for lab in points if sides[lab] == side), key=lambda q: float(np.dot(points[q], u)))
        if not labels:
            continue
        boxes = [Text((0.0, 0.0), lab, height=height, anchor=("center", "middle")).box() for lab in labels]
        wide = [(b[2] - b[0]) * WIDTH_MARGIN for b in boxes]
        tall = [b[3] - b[1] for b in boxes]
        along = [abs(u[0]) * w + abs(u[1]) * t + 1.2 for w, t in zip(wide, tall)]
        across = [abs(n[0]) * w + abs(n[1]) * t for w, t in zip(wide, tall)]
        at = spread([float(np.dot(np.asarray(points[q]) - centre, u)) for q in labels], along)
        base = max(side * float(np.dot(np.asarray(points[q]) - centre, n)) for q in labels)
        for k in offsets:
            items = [Text(tuple(centre + a * u + side * n * (base + k * height + c / 2)), lab, height=height,
                          anchor=("center", "middle")) for lab, a, c in zip(labels, at, across)]
            if all(placer.free(t.box()) for t in items):
                for lab, t in zip(labels, items):
                    placer.put(t)
                    leader(drawing, points[lab], t.box())
                edges[side] = base + k * height + max(across)
                break
        else:
            for lab in labels:
                t = placer.place(points[lab], lab, height, prefer=side * n, rings=(1.0, 2.0, 3.0, 4.5, 6.5, 9.0))
                if t is not None:
                    leader(drawing, points[lab], t.box())
    return edges
