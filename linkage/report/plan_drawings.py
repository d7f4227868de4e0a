"""Drawings of the graphical method, to scale: plans of velocities and accelerations, force
polygons, Zhukovsky's lever and a sheet per position (docs/plans.md).

Every drawing is built in millimetres of paper: a vector v is drawn ``|v| / mu`` mm long, with the
scale ``mu`` written on the drawing as students write it (``μ_v = 0.01 (m/s)/mm``). The standalone
drawings are true to size: printed at 100 %, 1 mm of the drawing is 1 mm of paper, so a teacher
can lay a student's sheet drawn at the same scale over them. Scales are given, or chosen
automatically among 1, 2, 2.5, 4 and 5 times a power of ten so that the largest vector is about
:data:`TARGET_MM` long. Plans are drawn without axes, as on paper: the pole, the images of the
points in lower-case letters (a point of a guide link under a slider's point A carries the guide's
number, ``a₃``), the vectors as arrows coloured by their link, and a table of every vector's
length on the drawing and its value.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import numpy as np, linkage
>>> from linkage.kinetostatics.plans import build_plans
>>> from linkage.report.plan_drawings import draw_plan, nice_scale
>>> plans = build_plans(linkage.analyze(linkage.load("slider_crank"), np.radians([45.0]), omega=-10.0))
>>> fig = draw_plan(plans, 0, "velocity", scale=0.01)
>>> print(next(t.get_text() for t in fig.texts if "(m/s)/mm" in t.get_text()))
Plan of velocities:  $\\mu_v$ = 0.01 (m/s)/mm
>>> nice_scale(0.0113)
0.02
>>> matplotlib.pyplot.close("all")
"""

from __future__ import annotations

import math
import re
import textwrap
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np

from assur.base import OK

from ..errors import InputError
from ..kinetostatics.plans import POLE, ForcePolygon, Plans
from .drawing import convex_hull, draw_mechanism
from .labels import Drawn, Label, place_labels
from .style import FONT, LINK_COLOURS, SMALL, pyplot
from .words import position_caption, subscript

__all__ = ["TARGET_MM", "nice_scale", "drawing_scales", "draw_plan", "draw_force_polygons", "draw_lever", "draw_sheet",
           "write_plan_drawings"]

#: the longest vector of a plan (the span of a force polygon) at an automatic scale is at most this
#: long, and over half as long (the students' scales step by at most 2): 60-120 mm, mm
TARGET_MM = 120.0
#: millimetres per inch
INCH = 25.4
#: the mantissas of a scale (students' scales: 1, 2, 2.5, 4, 5 times a power of ten)
MANTISSAS = (1.0, 2.0, 2.5, 4.0, 5.0, 10.0)
#: resolution of the PNG drawings, dots per inch
DPI = 150
#: vectors shorter than this are not drawn (their length is listed), mm
SHORTEST_MM = 0.3
#: distances of the candidate places of a point's label from the point, mm
RINGS_MM = (1.4, 2.6, 4.2, 6.5, 9.5)
#: a point's label farther than this from its point is joined to it by a thin line, mm
LEADER_MM = 6.0
#: a vector's label whose best place still costs this much (it would cover another label, a point or
#: long stretches of lines) is left out: the table names the vector
DROP_COST = 1000.0
#: vectors shorter than this carry no label on the drawing (the table names them), mm
LABELLED_MM = 7.0
#: room around a drawing for the labels, mm
MARGIN_MM = 9.0

#: per plan: its scale's symbol, the scale's unit, the unit of its vectors, the pole's letter
_SYMBOLS = {"velocity": (r"$\mu_v$", "(m/s)/mm", "m/s", "p"),
            "acceleration": (r"$\mu_a$", "(m/s²)/mm", "m/s²", "π")}
MU_F = r"$\mu_F$"
PLURAL = {"velocity": "velocities", "acceleration": "accelerations"}
_FORCE_COLOURS = {"reaction": "#222222", "known": "#7f7f7f", "internal": "#8e44ad"}


def nice_scale(per_mm: float) -> float:
    """The smallest students' scale at least ``per_mm`` (units per mm): 1, 2, 2.5, 4 or 5 times a
    power of ten.

    >>> nice_scale(0.0113), nice_scale(3.0), nice_scale(40.0)
    (0.02, 4.0, 40.0)
    """
    if not (per_mm > 0 and math.isfinite(per_mm)):
        return 1.0
    power = 10.0 ** math.floor(math.log10(per_mm))
    for m in MANTISSAS:
        if m * power >= per_mm * (1 - 1e-12):
            return float(f"{m * power:.6g}")
    return float(f"{10 * power:.6g}")


def _number(x: float) -> str:
    """``x`` to 4 significant digits (whole numbers from 10 000 up to 1e9, as a student writes them)
    with a true minus sign and no "−0"."""
    text = f"{x:.0f}" if 1e4 <= abs(x) < 1e9 else f"{x:.4g}"
    return ("0" if float(text) == 0 else text).replace("-", "−")


def _factor(x: float) -> str:
    """A number as a factor: in parentheses when negative."""
    return f"({_number(x)})" if _number(x).startswith("−") else _number(x)


# ----------------------------------------------------------------------------------------------
# names as students write them
# ----------------------------------------------------------------------------------------------


def _math(name: str) -> str:
    """A point name in mathtext: ``S2`` -> ``S_{2}``, ``A(3)`` -> ``A_{3}``, ``O1(3)`` -> ``O_{1,3}``."""
    m = re.fullmatch(r"([A-Za-z]+)(\d*)(?:\(([^)]+)\))?('*)", name)
    if not m:
        return r"\mathrm{" + re.sub(r"([_$%#&{}^~\\])", r"\\\1", name) + "}"
    letters, digits, link, primes = m.groups()
    head = letters if len(letters) == 1 else r"\mathrm{" + letters + "}"
    sub = ",".join(x for x in (digits, link) if x)
    return head + (f"_{{{sub}}}" if sub else "") + primes


def _image_name(label: str, pole: str) -> str:
    """The image of a point in lower case: ``B`` -> b, ``A(3)`` -> a₃, ``n(B,A)`` -> n_BA, ``k(A,3)`` -> k_A."""
    if label == POLE:
        return pole
    m = re.fullmatch(r"n\((.+),(.+)\)", label)
    if m:
        return f"$n_{{{_math(m.group(1))}{_math(m.group(2))}}}$"
    m = re.fullmatch(r"k\((.+),(.+)\)", label)
    if m:
        return f"$k_{{{_math(m.group(1))}}}$"
    return f"${_math(_lower(label))}$"


def _lower(label: str) -> str:
    m = re.fullmatch(r"([A-Za-z]+)(.*)", label)
    return m.group(1).lower() + m.group(2) if m else label


def _vector_name(v, quantity: str) -> str:
    """``v_A``, ``v_BA``, ``v_{AA₃}``, ``a^n_BA``, ``a^τ_BA``, ``a^k_{AA₃}``, ``a^r_{AA₃}`` in mathtext."""
    s = "v" if quantity == "velocity" else "a"
    if v.kind == "absolute":
        return f"${s}_{{{_math(v.point)}}}$"
    top = {"normal": "^{n}", "tangential": r"^{\tau}", "coriolis": "^{k}"}.get(v.kind, "")
    if v.kind == "relative-slide" and quantity == "acceleration":
        top = "^{r}"
    return f"${s}{top}_{{{_math(v.point)}{_math(v.about)}}}$"


def _force_name(label: str) -> str:
    """``G2`` -> G₂, ``Fi2`` -> F_i2, ``FB`` -> F_B, ``R[2,1]`` -> R₂₁, ``Mi3`` -> M_i3 (mathtext)."""
    m = re.fullmatch(r"([RM])\[(.+),(.+)\](?:\((.+)\))?", label)
    if m:
        head, i, j, pair = m.groups()
        sub = subscript(i) + subscript(j) if len(i) == len(j) == 1 else subscript(f"{i},{j}")
        return f"${head}_{{{sub}}}$" + (f" ({pair})" if pair else "")
    m = re.fullmatch(r"(G|Fi|Mi|Mb)(.+)", label)
    if m:                                               # of a link: G2, Fi2, Mi2, Mb4
        head, link = m.groups()
        return f"${head[0]}_{{{head[1:]}{subscript(link)}}}$"
    m = re.fullmatch(r"([FM])(.+)", label)
    if m:                                               # a force at a point (FB), a moment on a link (M3)
        return f"${m.group(1)}_{{{_math(m.group(2))}}}$"
    return label


# ----------------------------------------------------------------------------------------------
# a drawing on paper, in mm
# ----------------------------------------------------------------------------------------------


@dataclass
class _Arrow:
    start: np.ndarray
    end: np.ndarray
    colour: str
    width: float = 1.3
    dashed: bool = False
    label: str = ""


@dataclass
class _Sketch:
    """What one drawing holds, in mm of paper: arrows, thin lines, labelled dots, text lines."""

    arrows: list[_Arrow] = field(default_factory=list)
    lines: list[tuple[np.ndarray, str]] = field(default_factory=list)
    dots: list[tuple[np.ndarray, str, bool]] = field(default_factory=list)    # (xy, label, is the pole)
    title: list[str] = field(default_factory=list)
    table: list[tuple[str, ...]] = field(default_factory=list)   # rows of cells (mathtext only in the first)
    footer: list[str] = field(default_factory=list)              # lines under the table

    def extent(self) -> tuple[float, float, float, float]:
        pts = [np.zeros(2)] + [a.start for a in self.arrows] + [a.end for a in self.arrows]
        pts += [p for line, _ in self.lines for p in line] + [d[0] for d in self.dots]
        pts = np.array(pts, dtype=float)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1])


def _sketch_size(sketch: _Sketch) -> tuple[float, float]:
    x0, x1, y0, y1 = sketch.extent()
    return x1 - x0 + 2 * MARGIN_MM, y1 - y0 + 2 * MARGIN_MM


def _draw(ax, sketch: _Sketch, limits: tuple[float, float, float, float]) -> None:
    """Draw ``sketch`` into ``ax`` whose limits are ``limits`` (mm), without axes, and place its
    labels where they cover no arrow, dot or other label."""
    from matplotlib.patches import FancyArrowPatch

    x0, x1, y0, y1 = limits
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()
    for line, colour in sketch.lines:
        ax.plot(line[:, 0], line[:, 1], color=colour, lw=0.7, alpha=0.55, zorder=1, solid_capstyle="round")
    for a in sketch.arrows:
        if np.hypot(*(a.end - a.start)) < SHORTEST_MM or not np.all(np.isfinite([*a.start, *a.end])):
            continue
        ax.add_patch(FancyArrowPatch(tuple(a.start), tuple(a.end), arrowstyle="-|>", mutation_scale=7 + 2 * a.width,
                                     lw=a.width, color=a.colour, ls=(0, (4, 2)) if a.dashed else "-",
                                     shrinkA=0, shrinkB=0, zorder=3))
    for xy, _, pole in sketch.dots:
        ax.plot(*xy, marker="o", ms=4.5 if pole else 2.6, color="black", zorder=5)
    _place_labels(ax, sketch)


def _place_labels(ax, sketch: _Sketch) -> None:
    """Point labels around their dots, vector labels beside their arrows: each the candidate of
    least cost (on another label, on an arrow or a dot, outside the axes, far from its place), in
    mm of the drawing (:func:`~linkage.report.labels.place_labels`). A vector's label with no free
    place is left out (the table names the vector); a point's label far from its dot gets a leader."""
    fig = ax.figure
    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    box = ax.get_window_extent(renderer)
    mm_per_px = (x1 - x0) / box.width
    drawn = [a for a in sketch.arrows if np.hypot(*(a.end - a.start)) >= SHORTEST_MM]
    segments = np.array([[*a.start, *a.end] for a in drawn] + [[*ln[k], *ln[k + 1]] for ln, _ in sketch.lines
                                                             for k in range(len(ln) - 1)], dtype=float).reshape(-1, 4)
    obstacles = Drawn()
    obstacles.segments = [segments[np.all(np.isfinite(segments), axis=1)]]
    obstacles.discs = [(p, 1.2) for p in np.array([d[0] for d in sketch.dots], dtype=float).reshape(-1, 2)]
    angles = np.radians(np.arange(0, 360, 22.5) + 45)
    rings = np.array(RINGS_MM)
    a = np.tile(angles, len(rings))
    around = np.stack([np.cos(a), np.sin(a)], axis=1)
    labels, anchors = [], []
    for xy, label, _ in sketch.dots:
        if label:
            text = ax.text(0, 0, label, fontsize=FONT, ha="center", va="center", zorder=8, color="black",
                           bbox=dict(boxstyle="square,pad=0.05", fc="white", ec="none", alpha=0.8))
            labels.append(Label(text, xy, around, np.repeat(rings, len(angles)),
                                4.0 * np.repeat(np.arange(len(rings)), len(angles))))
            anchors.append(xy)
    for arrow in sorted((a for a in drawn if a.label and np.hypot(*(a.end - a.start)) >= LABELLED_MM),
                        key=lambda a: np.hypot(*(a.end - a.start))):     # the shortest, least free, first
        text = ax.text(0, 0, arrow.label, fontsize=SMALL, ha="center", va="center", zorder=8, color=arrow.colour,
                       bbox=dict(boxstyle="square,pad=0.05", fc="white", ec="none", alpha=0.8))
        u = arrow.end - arrow.start
        length = np.hypot(*u)
        u = u / length
        n = np.array([-u[1], u[0]])
        along = np.array([0.5, 0.38, 0.62, 0.25, 0.75])
        side = np.array([1.0, -1.0])
        gap = np.array([0.8, 2.2, 4.0, 6.5])
        t, s, g = (x.ravel() for x in np.meshgrid(along, side, gap, indexing="ij"))
        labels.append(Label(text, arrow.start + (t * length)[:, None] * u, s[:, None] * n, g,
                            6.0 * np.abs(t - 0.5) + 2.0 * g, drop=DROP_COST))   # no free place: the table names it
        anchors.append(None)
    places = place_labels(labels, obstacles, (x0, y0, x1, y1), renderer, per_px=mm_per_px, line_cost=80.0,
                          clearance=0.3)
    for label, xy, place in zip(labels, anchors, places):
        if place is None:
            continue
        label.text.set_position(tuple(place.centre))
        if xy is not None and np.hypot(*(place.centre - xy)) > LEADER_MM:      # far from its dot: a leader
            size = np.array([place.width, place.height])
            edge = place.centre - np.clip(place.centre - xy, -size / 2, size / 2)
            ax.plot([xy[0], edge[0]], [xy[1], edge[1]], color="0.45", lw=0.5, zorder=7)


# ----------------------------------------------------------------------------------------------
# the sketches
# ----------------------------------------------------------------------------------------------


def _colours(mech) -> dict[str, str]:
    return {k: LINK_COLOURS[n % len(LINK_COLOURS)] for n, k in enumerate(mech.moving_links)}


def _figure(sk: _Sketch, pts: list[np.ndarray], colour: str, closed_only: bool = False) -> None:
    """The outline of a link's images (their convex hull: a segment for points on a line); with
    ``closed_only`` only when it encloses an area (a segment is drawn by the plan's vectors)."""
    pts = np.array(pts, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if len(pts) < 2:
        return
    hull = convex_hull(pts)
    if len(hull) >= 3:
        sk.lines.append((np.vstack([hull, hull[:1]]), colour))
    elif len(hull) == 2 and not closed_only:
        sk.lines.append((hull, colour))


def _plan_scale(plans: Plans, i: int, quantity: str, target: float = TARGET_MM) -> float:
    plan = getattr(plans, quantity)
    largest = max([float(np.hypot(*img[i])) for img in plan.images.values()] +
                  [float(np.hypot(*v.vector[i])) for v in plan.vectors] + [0.0])
    return nice_scale(largest / target) if largest > 0 else 1.0


def _plan_sketch(plans: Plans, i: int, quantity: str, scale: float, *, table: bool = True) -> _Sketch:
    plan = getattr(plans, quantity)
    mech = plans.motion.mechanism
    colour = _colours(mech)
    mu, unit_mm, unit, pole = _SYMBOLS[quantity]
    sk = _Sketch()
    at = {label: img[i] / scale for label, img in plan.images.items()}
    at[POLE] = np.zeros(2)
    for link, labels in plan.links.items():   # the figure of each link: similar to the link
        _figure(sk, [at[q] for q in labels if q in at], colour[link], closed_only=True)
    for v in plan.vectors:
        if v.role == "similarity":
            continue
        start, end = at[v.start], at[v.start] + v.vector[i] / scale
        if v.kind == "absolute":
            sk.arrows.append(_Arrow(start, end, "0.25", 0.8))
        elif v.kind == "relative" and quantity == "acceleration":   # the sum of its two parts, drawn
            sk.arrows.append(_Arrow(start, end, colour.get(v.link, "black"), 0.7, dashed=True))
        else:
            sk.arrows.append(_Arrow(start, end, colour.get(v.link, "black"), 1.4, label=_vector_name(v, quantity)))
    # one label per place: images that coincide (the frame's points at the pole) share it
    groups: list[tuple[np.ndarray, list[str]]] = []
    frame = mech.frame
    for label, xy in at.items():
        if label != POLE and (plans.velocity.images.get(label) is not None and label in mech.point_names
                              and mech.point_link(label) == frame):
            continue
        for place, names in groups:
            if np.hypot(*(place - xy)) < 0.5:
                names.append(label)
                break
        else:
            groups.append((xy, [label]))
    for xy, names in groups:
        names.sort(key=lambda q: (q != POLE, q))
        text = ", ".join(_image_name(q, pole) for q in names)
        sk.dots.append((xy, text, POLE in names))
    sk.title = [f"Plan of {PLURAL[quantity]}:  {mu} = {_number(scale)} {unit_mm}"]
    if table:
        sk.table = _plan_table(plans, i, quantity, scale)
    return sk


def _plan_table(plans: Plans, i: int, quantity: str, scale: float) -> list[tuple[str, ...]]:
    """Rows (vector = its ends, length on the drawing, value): the value is the length times the
    scale. Then the angular velocities or accelerations of the links."""
    plan = getattr(plans, quantity)
    _, _, unit, pole = _SYMBOLS[quantity]
    rows = [("vector", "length", "value = length · μ")]
    for v in plan.vectors:
        if v.role == "similarity":
            continue
        value = float(np.hypot(*v.vector[i]))
        rows.append((f"{_vector_name(v, quantity)} = {_image_name(v.start, pole)}{_image_name(v.end, pole)}",
                     f"{value / scale:.1f} mm", f"{_number(value)} {unit}"))
    motion_of = plans.angular_velocity if quantity == "velocity" else plans.angular_acceleration
    sym, u = (r"\omega", "rad/s") if quantity == "velocity" else (r"\varepsilon", "rad/s²")
    for k, w in motion_of.items():
        rows.append((f"${sym}_{subscript(k)}$", "", f"{_number(float(w[i]))} {u}"))
    return rows


def _polygon_sketch(polygon: ForcePolygon, i: int, scale: float, colour: Mapping[str, str]) -> _Sketch:
    """The forces head to tail from the origin: loads in their link's colour, the reactions the
    step finds black, those of later groups grey; a dyad's internal reaction dashed, from the end
    of its first link's forces back to the start."""
    sk = _Sketch()
    here = np.zeros(2)
    first_link_end = None
    for f in polygon.forces:
        step = f.vector[i] / scale
        if f.kind == "reaction":
            col, width = (_FORCE_COLOURS["reaction"], 1.6) if f.unknown else (_FORCE_COLOURS["known"], 1.1)
        else:
            col, width = colour.get(f.link, "black"), 1.2
        sk.arrows.append(_Arrow(here, here + step, col, width, label=_force_name(f.label)))
        here = here + step
        if f.link == polygon.links[0]:
            first_link_end = here
    if len(polygon.links) == 2 and len(polygon.internal) == 1 and first_link_end is not None:
        inner = polygon.internal[0]
        sk.arrows.append(_Arrow(first_link_end, first_link_end + inner.vector[i] / scale, _FORCE_COLOURS["internal"],
                                1.1, dashed=True, label=_force_name(inner.label)))
    sk.dots.append((np.zeros(2), "", False))
    return sk


def _polygon_scale(polygon: ForcePolygon, i: int, target: float = TARGET_MM) -> float:
    vectors = [f.vector[i] for f in polygon.forces]
    if not vectors:
        return 1.0
    chain = np.cumsum(np.array(vectors), axis=0)
    span = max(float(np.ptp(np.vstack([np.zeros(2), chain]), axis=0).max()),
               max(float(np.hypot(*v)) for v in vectors))
    return nice_scale(span / target) if span > 0 else 1.0


def _polygon_table(polygon: ForcePolygon, i: int, scale: float) -> list[tuple[str, ...]]:
    rows = [("force", "length", "value = length · μ")]
    for f in [*polygon.forces, *polygon.internal]:
        value = float(np.hypot(*f.vector[i]))
        rows.append((_force_name(f.label), f"{value / scale:.1f} mm", f"{_number(value)} N"))
    for m in polygon.moments:
        rows.append((_force_name(m.label), "", f"{_number(float(m.value[i]))} N·m"))
    return rows


def _lever_sketch(plans: Plans, i: int, scale: float, force_scale: float) -> _Sketch:
    mech = plans.motion.mechanism
    colour = _colours(mech)
    plan = plans.velocity
    sk = _Sketch()

    def turned(v):          # the plan turned by -90 degrees (clockwise)
        return np.array([v[1], -v[0]]) / scale

    at = {label: turned(img[i]) for label, img in plan.images.items()}
    at[POLE] = np.zeros(2)
    for link, labels in plan.links.items():
        _figure(sk, [at[q] for q in labels if q in at], colour[link])
    for v in plan.vectors:
        if v.kind == "absolute":
            sk.lines.append((np.array([at[POLE], at[v.end]]), "0.55"))
    frame_points = {q for q in plan.images if q in mech.point_names and mech.point_link(q) == mech.frame}
    for label, xy in at.items():
        if label == POLE:
            sk.dots.append((xy, "p", True))
        elif label not in frame_points and np.hypot(*xy) >= 0.5:
            sk.dots.append((xy, _image_name(label, "p"), False))
    for f in plans.lever.forces:
        start = at[f.point]
        sk.arrows.append(_Arrow(start, start + f.force[i] / force_scale, colour.get(f.link, "black"), 1.2,
                                label=_force_name(f.label)))
    sk.title = [f"Zhukovsky's lever: the velocity plan turned 90° clockwise, $\\mu_v$ = {_number(scale)} (m/s)/mm; "
                f"forces at the images of their points, {MU_F} = {_number(force_scale)} N/mm"]
    lever = plans.lever
    size = max([abs(float(f.moment[i])) for f in lever.forces] + [abs(float(m.contribution[i]))
                                                                     for m in lever.moments] + [1e-300])

    def moment(x: float) -> str:         # round-off of a force through the pole reads 0
        return _number(x if abs(x) > 1e-12 * size else 0.0)

    rows = [("force at its image", "arm", "moment about p")]
    for f in lever.forces:
        magnitude = float(np.hypot(*f.force[i]))
        arm = abs(float(f.moment[i])) / magnitude / scale if magnitude > 0 else 0.0
        rows.append((f"{_force_name(f.label)} at {_image_name(f.point, 'p')}", f"h = {arm:.1f} mm",
                     f"{moment(float(f.moment[i]))} N·m/s"))
    for m in lever.moments:
        rows.append((f"{_force_name(m.label)}·$\\omega_{subscript(m.link)}$",
                     f"{_number(float(m.value[i]))} · {_factor(float(m.angular_velocity[i]))}",
                     f"{moment(float(m.contribution[i]))} N·m/s"))
    omega = float(lever.omega[i])
    sk.table = rows
    sk.footer = [f"$M_b$ = −ΣM / ω₁ = −{_factor(-float(lever.balancing_moment[i]) * omega)} / {_factor(omega)} = "
                 f"{_number(float(lever.balancing_moment[i]))} N·m;   the kinetostatics: "
                 f"{_number(float(plans.reactions.balancing_moment[i]))} N·m"]
    return sk


def _lever_fit(plans: Plans, i: int, room_w: float, room_h: float, smallest: float = 0.0) -> tuple[float, float]:
    """The scales of the plan (``smallest`` or larger) and of the forces of a lever that fits
    ``room_w`` by ``room_h`` mm."""
    turned = np.array([img[i] for img in plans.velocity.images.values()] + [np.zeros(2)])
    span = np.ptp(turned, axis=0)[::-1]
    scale = max(smallest, nice_scale(max(span[0] / room_w, span[1] / room_h, 1e-300)))
    force_scale = _lever_force_scale(plans, i, target=max(0.25 * float(min(span.max() / scale, room_h)), 8.0))
    for _ in range(20):
        x0, x1, y0, y1 = _lever_sketch(plans, i, scale, force_scale).extent()
        if x1 - x0 <= room_w and y1 - y0 <= room_h:
            break
        scale, force_scale = nice_scale(scale * 1.001), nice_scale(force_scale * 1.001)
    return scale, force_scale


def _lever_force_scale(plans: Plans, i: int, target: float = 25.0) -> float:
    largest = max([float(np.hypot(*f.force[i])) for f in plans.lever.forces] + [0.0])
    return nice_scale(largest / target) if largest > 0 else 1.0


def drawing_scales(plans: Plans, position: int, given: Mapping[str, object] | None = None) -> dict[str, object]:
    """The scales of every drawing of one position, the standalone ones and the sheet's alike:
    ``velocity`` ((m/s)/mm), ``acceleration`` ((m/s²)/mm) and ``force`` (step -> N/mm), the
    ``given`` ones (``force``: one number for every polygon, or step -> number) else those chosen
    automatically: the students' scale that draws the longest vector 60-120 mm long
    (:data:`TARGET_MM`), or a larger one where the drawing would not fit its cell of the sheet."""
    i = _check(plans, position)
    given = dict(given or {})
    forces = given.get("force")
    room = _sheet_room(plans)

    def fitted(chosen: float, unit_sketch: _Sketch) -> float:
        x0, x1, y0, y1 = unit_sketch.extent()
        return max(chosen, nice_scale(max((x1 - x0) / room[0], (y1 - y0) / room[1], 1e-300)))

    colour = _colours(plans.motion.mechanism)
    plan = {q: given.get(q) or fitted(_plan_scale(plans, i, q), _plan_sketch(plans, i, q, 1.0, table=False))
            for q in ("velocity", "acceleration")}
    return {**plan, "force": {p.step: (forces.get(p.step) if isinstance(forces, Mapping) else forces)
                              or fitted(_polygon_scale(p, i), _polygon_sketch(p, i, 1.0, colour))
                              for p in plans.polygons}}


# ----------------------------------------------------------------------------------------------
# figures
# ----------------------------------------------------------------------------------------------

#: the narrowest figure, mm (its header fits in it)
MIN_WIDTH_MM = 170.0
#: average width of a character at 10 pt, mm
CHAR_MM = 2.1
#: height of a line of text, mm (10 pt with spacing)
LINE_MM = 5.0
#: width of a column of a table under a drawing, mm
COLUMN_MM = 106.0
#: where the cells of a row of such a table begin, mm from the column's left
CELL_MM = (0.0, 34.0, 68.0)
#: height of a line of such a table, mm
TABLE_LINE_MM = 4.4
#: lines per column of such a table
COLUMN_LINES = 16


def _true_scale_figure(sketches: Sequence[_Sketch], header: Sequence[str]):
    """A figure holding the sketches side by side at true size (1 mm of data = 1 mm of paper),
    each with its title above and its table below; ``header`` lines on top."""
    plt = pyplot()
    pad = 8.0
    sizes = [_sketch_size(sk) for sk in sketches]
    columns = [len(_table_columns(sk.table)) for sk in sketches]
    cells = [max(w, 45.0, c * COLUMN_MM) for (w, _), c in zip(sizes, columns)]
    width = sum(cells) + pad * (len(sketches) + 1)
    if width < MIN_WIDTH_MM:
        cells = [c + (MIN_WIDTH_MM - width) / len(cells) for c in cells]
        width = MIN_WIDTH_MM
    header = [part for line in header for part in textwrap.wrap(line, int((width - 2 * pad) / CHAR_MM))]
    titles = [[part for line in sk.title for part in textwrap.wrap(line, int(cell / CHAR_MM))]
              for sk, cell in zip(sketches, cells)]
    head_h = len(header) * LINE_MM + 4
    title_h = max(len(t) for t in titles) * LINE_MM + 2
    draw_h = max(h for _, h in sizes)
    rows = max(min(len(sk.table), COLUMN_LINES) for sk in sketches)
    table_h = rows * TABLE_LINE_MM + (4 if rows else 0)
    footer = max(len(sk.footer) for sk in sketches)
    table_h += footer * LINE_MM + (2 if footer else 0)
    height = head_h + title_h + draw_h + table_h + pad
    fig = plt.figure(figsize=(width / INCH, height / INCH), dpi=DPI)   # its labels are measured as drawn

    def text(x, y, line, size=FONT):
        fig.text(x / width, y / height, line, fontsize=size, ha="left", va="baseline")

    for k, line in enumerate(header):
        text(pad, height - 4 - (k + 0.8) * LINE_MM, line)
    left = pad
    top = height - head_h
    for sk, title, (w, h), cell in zip(sketches, titles, sizes, cells):
        for k, line in enumerate(title):
            text(left, top - (k + 0.8) * LINE_MM, line)
        ax = fig.add_axes(((left + (cell - w) / 2) / width, (top - title_h - h) / height, w / width, h / height))
        x0, x1, y0, y1 = sk.extent()
        _draw(ax, sk, (x0 - MARGIN_MM, x1 + MARGIN_MM, y0 - MARGIN_MM, y1 + MARGIN_MM))
        for col, rows_of_column in enumerate(_table_columns(sk.table)):
            for row, row_cells in enumerate(rows_of_column):
                for content, offset in zip(row_cells, CELL_MM):
                    text(left + col * COLUMN_MM + offset, top - title_h - draw_h - 4 - (row + 0.8) * TABLE_LINE_MM,
                         content, SMALL - 1)
        below = top - title_h - draw_h - 4 - min(len(sk.table), COLUMN_LINES) * TABLE_LINE_MM - 2
        for k, line in enumerate(sk.footer):
            text(left, below - (k + 0.8) * LINE_MM, line, SMALL)
        left += cell + pad
    return fig


def _table_columns(table: list[tuple[str, ...]]) -> list[list[tuple[str, ...]]]:
    """A table's rows in columns of at most :data:`COLUMN_LINES` lines, each under the header row."""
    per = COLUMN_LINES - 1
    return [[table[0], *table[1 + k:1 + k + per]] for k in range(0, max(len(table) - 1, 1), per)] if table else []


def _header(plans: Plans, i: int) -> list[str]:
    motion = plans.motion
    mech = motion.mechanism
    caption = position_caption(motion, i).replace("\n", " ")
    omega, eps = float(motion.omega[i]), float(motion.eps[i])
    return [f"{mech.name}: {caption}",
            f"ω₁ = {_number(omega)} rad/s, ε₁ = {_number(eps)} rad/s²"]


def _check(plans: Plans, position: int) -> int:
    n = len(plans.motion.phi)
    if not isinstance(position, (int, np.integer)) or not -n <= position < n:
        raise InputError(f"position must be an index of the {n} analysed angles, got {position!r}")
    i = int(position) % n
    if plans.motion.status[i] != OK:
        raise InputError(f"mechanism '{plans.motion.mechanism.name}' is not assembled or is singular at the "
                         f"input angle {np.degrees(plans.motion.phi[i]):.6g} deg: it has no plans there")
    return i


def draw_plan(plans: Plans, position: int, quantity: str = "velocity", *, scale: float | None = None):
    """The plan of velocities or accelerations at one position, true to size.

    Parameters
    ----------
    plans : Plans
        From :func:`linkage.kinetostatics.plans.build_plans`.
    position : int
        Index of the position in ``plans.motion.phi`` (0 is the first).
    quantity : {"velocity", "acceleration"}
    scale : float, optional
        ``μ_v`` in (m/s)/mm or ``μ_a`` in (m/s²)/mm (default: chosen, :func:`nice_scale`).

    Returns
    -------
    matplotlib Figure
        Its texts: the header (scheme, position, ω, ε), the title with the scale, the table.
    """
    if quantity not in _SYMBOLS:
        raise InputError(f"quantity must be 'velocity' or 'acceleration', got {quantity!r}")
    i = _check(plans, position)
    scale = drawing_scales(plans, i)[quantity] if scale is None else _positive(scale, "scale")
    return _true_scale_figure([_plan_sketch(plans, i, quantity, scale)], _header(plans, i))


def _positive(value: float, what: str) -> float:
    if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value) and value > 0):
        raise InputError(f"{what} must be a positive number (units per mm), got {value!r}")
    return float(value)


def draw_force_polygons(plans: Plans, position: int, *, scales: Mapping[str, float] | float | None = None):
    """The force polygon of every step (the input links, then the groups) at one position, side by
    side, each at its own force scale ``μ_F`` (N/mm), true to size.

    ``scales``: one scale for all, or step -> scale (``{"II-RRR(2,3)": 50.0}``); default chosen
    per polygon. The reactions this step finds are black, those of later groups grey, the
    internal reaction of a dyad dashed (it closes the polygon of the group's first link).
    """
    i = _check(plans, position)
    colour = _colours(plans.motion.mechanism)
    chosen = drawing_scales(plans, i, {"force": scales})["force"]
    sketches = []
    for polygon in plans.polygons:
        scale = _positive(chosen[polygon.step], "force scale")
        sk = _polygon_sketch(polygon, i, scale, colour)
        sk.title = [f"Forces on {polygon.step}:  {MU_F} = {_number(scale)} N/mm"]
        sk.table = _polygon_table(polygon, i, scale)
        sketches.append(sk)
    header = _header(plans, i) + ["$R_{ij}$: the force of link j on link i; black: the reactions each step finds, "
                                  "grey: those of later groups, dashed: the reaction between a dyad's links; "
                                  "moments are listed, not drawn"]
    return _true_scale_figure(sketches, header)


def draw_lever(plans: Plans, position: int, *, scale: float | None = None, force_scale: float | None = None):
    """Zhukovsky's lever at one position: the plan of velocities turned by 90° clockwise with every
    force at its image point, the arms and moments of the forces, and the balancing moment it
    gives next to the kinetostatic one. ``scale``: μ_v, (m/s)/mm; ``force_scale``: μ_F of the
    arrows, N/mm (defaults: chosen)."""
    i = _check(plans, position)
    scale = drawing_scales(plans, i)["velocity"] if scale is None else _positive(scale, "scale")
    force_scale = _lever_force_scale(plans, i) if force_scale is None else _positive(force_scale, "force scale")
    return _true_scale_figure([_lever_sketch(plans, i, scale, force_scale)], _header(plans, i))


# ----------------------------------------------------------------------------------------------
# the sheet
# ----------------------------------------------------------------------------------------------

#: the sheet: A3 landscape; its header, the gap between its cells and a cell's title, mm
SHEET = (420.0, 297.0)
SHEET_HEAD, SHEET_PAD, SHEET_TITLE = 16.0, 7.0, 9.0


def _sheet_cells(plans: Plans) -> tuple[int, int, float, float]:
    """Columns, rows, width and height (mm) of the cells of :func:`draw_sheet`."""
    cells = 3 + len(plans.polygons) + 1
    ncols = max(3, math.ceil(cells / 2))
    nrows = math.ceil(cells / ncols)
    width, height = SHEET
    return (ncols, nrows, (width - SHEET_PAD * (ncols + 1)) / ncols,
            (height - SHEET_HEAD - SHEET_PAD * nrows) / nrows)


def _sheet_room(plans: Plans) -> tuple[float, float]:
    """The room a drawing has in its cell of the sheet, inside its margins, mm."""
    _, _, cell_w, cell_h = _sheet_cells(plans)
    return cell_w - 2 * MARGIN_MM, cell_h - SHEET_TITLE - 2 * MARGIN_MM


def draw_sheet(plans: Plans, position: int, *, scales: Mapping[str, object] | None = None):
    """One sheet (A3 landscape, true to size when printed at 100 %) for one position: the
    mechanism to scale, the plans of velocities and accelerations, the force polygons and
    Zhukovsky's lever, each at the scale of every drawing of the position
    (:func:`drawing_scales`, ``scales`` given as there) written on it."""

    plt = pyplot()
    i = _check(plans, position)
    motion = plans.motion
    colour = _colours(motion.mechanism)
    shared = drawing_scales(plans, i, scales)
    ncols, nrows, cell_w, cell_h = _sheet_cells(plans)
    width, height = SHEET
    head_h, pad, title_h = SHEET_HEAD, SHEET_PAD, SHEET_TITLE
    fig = plt.figure(figsize=(width / INCH, height / INCH), dpi=DPI)
    for k, line in enumerate(_header(plans, i)):
        fig.text(pad / width, 1 - (5 + k * LINE_MM) / height, line, fontsize=FONT, ha="left", va="baseline")

    def rect(k, inner_w, inner_h):
        r, c = divmod(k, ncols)
        left = pad + c * (cell_w + pad)
        top = height - head_h - r * (cell_h + pad)
        return left, top, (left + (cell_w - inner_w) / 2) / width, (top - title_h - inner_h) / height

    room_w, room_h = cell_w, cell_h - title_h
    # the mechanism: its own drawing, at a scale that fills the cell
    left, top, *_ = rect(0, 0, 0)
    ax = fig.add_axes(((left + 12) / width, (top - title_h - room_h + 10) / height, (room_w - 14) / width,
                       (room_h - 12) / height))
    draw_mechanism(motion, i, ax=ax, caption=False)
    fig.text(left / width, (top - 0.8 * LINE_MM) / height, "Mechanism", fontsize=FONT, ha="left", va="baseline")
    panels = ["velocity", "acceleration", *(polygon.step for polygon in plans.polygons), "lever"]
    for k, what in enumerate(panels, start=1):
        if what in ("velocity", "acceleration"):
            scale = float(shared[what])
            sk = _plan_sketch(plans, i, what, scale, table=False)
            title = sk.title[0]
        elif what == "lever":
            scale, force_scale = _lever_fit(plans, i, room_w - 2 * MARGIN_MM, room_h - 2 * MARGIN_MM,
                                            float(shared["velocity"]))
            sk = _lever_sketch(plans, i, scale, force_scale)
            title = (f"Zhukovsky's lever (the plan turned 90° clockwise): $\\mu_v$ = {_number(scale)} (m/s)/mm, "
                     f"{MU_F} = {_number(force_scale)} N/mm; $M_b$ = "
                     f"{_number(float(plans.lever.balancing_moment[i]))} N·m")
        else:
            polygon = next(p for p in plans.polygons if p.step == what)
            scale = float(shared["force"][what])
            sk = _polygon_sketch(polygon, i, scale, colour)
            title = f"Forces on {what}:  {MU_F} = {_number(scale)} N/mm"
        w, h = _sketch_size(sk)
        left, top, fx, fy = rect(k, w, h)
        ax = fig.add_axes((fx, fy, w / width, h / height))
        x0, x1, y0, y1 = sk.extent()
        _draw(ax, sk, (x0 - MARGIN_MM, x1 + MARGIN_MM, y0 - MARGIN_MM, y1 + MARGIN_MM))
        for n, line in enumerate(textwrap.wrap(title, int(cell_w / (0.9 * CHAR_MM)))):
            fig.text(left / width, (top - (0.8 + 0.85 * n) * LINE_MM) / height, line, fontsize=SMALL, ha="left",
                     va="baseline")
    return fig


# ----------------------------------------------------------------------------------------------
# files
# ----------------------------------------------------------------------------------------------

#: the drawings :func:`write_plan_drawings` writes, by name
DRAWINGS = ("velocity", "acceleration", "forces", "lever", "sheet")


def write_plan_drawings(plans: Plans, position: int, folder: str | Path, *, formats: Iterable[str] = ("svg", "png"),
                        stem: str = "plans", scales: Mapping[str, float] | None = None, dpi: float = DPI,
                        drawings: Sequence[str] = DRAWINGS) -> list[Path]:
    """Write the drawings of one position into ``folder`` (created): ``<stem>_velocity``,
    ``<stem>_acceleration``, ``<stem>_forces``, ``<stem>_lever`` and ``<stem>_sheet``, in each of
    ``formats`` (``svg``, ``png``). ``scales``: ``velocity`` ((m/s)/mm), ``acceleration``
    ((m/s²)/mm), ``force`` (N/mm, every polygon), any of them (default: chosen); ``dpi``: of the
    PNG files; ``drawings``: which of :data:`DRAWINGS` to write. Returns the paths written."""
    plt = pyplot()
    formats = list(formats)
    bad = [f for f in formats if f not in ("svg", "png")]
    if bad:
        raise InputError(f"formats must be 'svg' or 'png', got {bad}")
    scales = dict(scales or {})
    unknown = sorted(set(scales) - {"velocity", "acceleration", "force"})
    if unknown:
        raise InputError(f"unknown scale(s) {unknown}: expected 'velocity', 'acceleration' or 'force'")
    unknown = sorted(set(drawings) - set(DRAWINGS))
    if unknown:
        raise InputError(f"unknown drawing(s) {unknown}: expected some of {list(DRAWINGS)}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    figures = {"velocity": lambda: draw_plan(plans, position, "velocity", scale=scales.get("velocity")),
               "acceleration": lambda: draw_plan(plans, position, "acceleration", scale=scales.get("acceleration")),
               "forces": lambda: draw_force_polygons(plans, position, scales=scales.get("force")),
               "lever": lambda: draw_lever(plans, position, scale=scales.get("velocity")),
               "sheet": lambda: draw_sheet(plans, position, scales=scales)}
    written = []
    for name in drawings:
        fig = figures[name]()
        try:
            for fmt in formats:
                path = folder / f"{stem}_{name}.{fmt}"
                if fmt == "png":
                    fig.savefig(path, dpi=dpi, metadata={"Software": None})
                else:
                    fig.savefig(path, metadata={"Date": None})
                written.append(path)
        finally:
            plt.close(fig)
    return written
