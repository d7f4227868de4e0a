"""Printable assignment sheets: one variant's A4 PDF, the mechanism drawn to scale (matplotlib only).

- :func:`assignment_sheet_from_given` -- a variant's sheet rendered from its ``given.json``
  alone (:mod:`~linkage.course.given`): the title block with the variant and empty fields for
  the student's name, group and date; the mechanism drawn to scale; the tasks; every datum the
  answer key depends on, in tables of quantity, symbol, value and unit; every load diagram as a
  small graph over the stroke with its zones and its table of values
  (:mod:`~linkage.course.diagram_blocks`); as many pages as the data need, numbered.
- :func:`assignment_sheet` -- a sheet of a mechanism with a data table and tasks given as text.

Both draw the mechanism **to a true standard scale** (1:1, 1:2, 1:2.5, 1:4, 1:5, 1:10 ... or
2:1, 5:1 ... for tiny mechanisms), the largest that fits the room page 1 leaves under the title,
at one table position with the sense of rotation of the input link, the output point's path and
the scale written out, so that a student measures lengths on the printed page with a ruler. What
follows the drawing goes under it while it fits, and to the next pages otherwise (a table or a
list of tasks longer than a page is split between rows). :func:`sheet_figures` and
:func:`given_sheet_figures` give the same pages as matplotlib figures (for a PNG, or to inspect
them). The overview of a set of variants is :mod:`~linkage.course.overview`'s; all are typeset
with :mod:`~linkage.course.typesetting`.

**To scale.** A4 is 210 x 297 mm and the figure is exactly that size, in inches; the drawing's
axes are placed in inches and their limits set so that one metre of the mechanism is exactly
``scale / 0.0254`` inches of paper in x and in y. The sheet says "print at actual size": a
printer's "fit to page" shrinks it (the 100 mm bar under the drawing checks the print).

**Reproducible.** The same input gives byte-identical PDFs (no dates, fixed metadata, embedded
fonts, matplotlib's built-in defaults; see :mod:`~linkage.course.typesetting`), and the
functions can run in worker processes. Without matplotlib they raise
:class:`~linkage.report.style.PlotExtraMissing`.

>>> import linkage
>>> pdf = assignment_sheet(linkage.load("course_slider_crank"), title="Assignment 1 — press",
...                        data=[("crank length OA", "0.0742", "m")], tasks=["Draw the mechanism"])
>>> pdf[:5], b"CreationDate" in pdf
(b'%PDF-', False)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..kinematics.motion import analyze
from ..model.mechanism import Mechanism, Prismatic
from ..model.scheme import section_of
from ..report.drawing import Geometry, draw_mechanism, rail_hatch, support
from ..report.results import declared_rotation, table_defaults, table_positions
from ..report.words import position_head
from .diagram_blocks import diagram_block
from .given import scheme_from_given, sheet_rows
from .typesetting import (
    A4,
    BOTTOM,
    FOOT,
    HEADING,
    MM,
    SIDE,
    TABLE,
    TEXT,
    TITLE,
    TOP,
    Block,
    Measure,
    flow,
    footer,
    line_height,
    new_page,
    page_style,
    paginate,
    pdf_bytes,
    rule,
    table_block,
    write,
)

__all__ = ["assignment_sheet", "assignment_sheet_from_given", "given_sheet_figures", "sheet_figures", "standard_scale",
           "scale_text", "table_motion"]

# the drawing's box: room for the y tick labels and axis label at the left, the x ones below
AXES_LEFT, AXES_RIGHT, AXES_BELOW, AXES_ABOVE = 0.62, 0.12, 0.46, 0.08
#: smallest height of the drawing's axes, inches (room for a few ticks on the y axis)
MIN_AXES = 1.3
#: height of the 100 mm check bar under the drawing, inches
BAR = 0.26
#: reductions 1:d with d = m 10^k (ISO 5455 and the usual 1:2.5, 1:4, 1:25, 1:40)
_REDUCTIONS = (1, 2, 2.5, 4, 5)
#: enlargements e:1 (ISO 5455)
_ENLARGEMENTS = (2, 5, 10, 20, 50, 100)


# ----------------------------------------------------------------------------------------------
# the scale
# ----------------------------------------------------------------------------------------------


def _standard_ratios(largest_denominator: float = 1e12) -> list[tuple[float, float]]:
    """Standard scales ``(paper, real)`` from the largest enlargement down, every reduction up to
    1:``largest_denominator``."""
    ratios = [(float(e), 1.0) for e in sorted(_ENLARGEMENTS, reverse=True)]
    k = 0
    while 10 ** k <= largest_denominator:
        ratios += [(1.0, float(m * 10 ** k)) for m in _REDUCTIONS if m * 10 ** k <= largest_denominator]
        k += 1
    return ratios


def standard_scale(extent: tuple[float, float], box: tuple[float, float]) -> tuple[float, float]:
    """The largest standard scale at which a drawing fits a box on paper.

    Parameters
    ----------
    extent : (width, height)
        Size of what is drawn, m (> 0).
    box : (width, height)
        Room on paper, inches (> 0).

    Returns
    -------
    (paper, real) : (float, float)
        The scale ``paper:real``: ``(1, 5)`` is 1:5 (1 mm on paper is 5 mm of the mechanism),
        ``(2, 1)`` is 2:1. Candidates: 100:1, 50:1, 20:1, 10:1, 5:1, 2:1, then 1:d with
        d = 1, 2, 2.5, 4, 5 times a power of ten.

    Raises
    ------
    InputError
        A size that is not a finite positive number.

    >>> standard_scale((0.45, 0.2), (6.4, 4.0))      # 0.45 m at 1:2.5 is 180 mm = 7.1 in: too wide
    (1.0, 4.0)
    >>> standard_scale((0.004, 0.003), (6.4, 4.0))
    (20.0, 1.0)
    """
    values = [*extent, *box]
    if not all(isinstance(v, (int, float, np.floating)) and math.isfinite(v) and v > 0 for v in values):
        raise InputError(f"the drawing's extent {extent!r} (m) and the box {box!r} (inches) must be finite and > 0")
    fits = [(p, r) for p, r in _standard_ratios()
            if all(e * p / r / 0.0254 <= b for e, b in zip(extent, box, strict=True))]
    if not fits:
        raise InputError(f"a drawing of {extent[0]:.6g} x {extent[1]:.6g} m fits no standard scale in a box of "
                         f"{box[0]:.3g} x {box[1]:.3g} in")
    return fits[0]


def scale_text(scale: tuple[float, float]) -> str:
    """``"1:5"``, ``"1:2.5"``, ``"2:1"`` for a scale ``(paper, real)``.

    >>> scale_text((1.0, 2.5)), scale_text((5.0, 1.0))
    ('1:2.5', '5:1')
    """
    return ":".join(f"{v:.10g}" for v in scale)



# ----------------------------------------------------------------------------------------------
# the table positions of a scheme
# ----------------------------------------------------------------------------------------------


def table_motion(mech: Mechanism):
    """The positions of the scheme's declared table, as ``linkage analyze`` tabulates them (its
    [dynamics] positions, start and rotation: :func:`linkage.report.results.table_positions`): a
    :class:`~linkage.Motion` of order 0; positions that do not assemble are masked (drawing one
    of them is an error)."""

    direction = declared_rotation(mech)
    phi, _ = table_positions(mech, *table_defaults(mech), direction)
    return analyze(mech, phi, order=0, on_failure="mask")


def _rotation(mech: Mechanism) -> int | None:
    """+1 / -1: the sign of the scheme's declared mean speed; None when it declares none."""

    spec = section_of(mech, "dynamics")
    return spec.rotation if spec is not None else None



# ----------------------------------------------------------------------------------------------
# the measured text of a sheet
# ----------------------------------------------------------------------------------------------


@dataclass
class _Sheet:
    """The measured text of an assignment sheet."""

    measure: Measure
    title: str
    subtitle: str
    data: list[tuple[str, str, str]]
    tasks: list[str]
    width: float = field(default=A4[0] - 2 * SIDE)

    def title_block(self, size: float = TITLE) -> Block:
        title = self.measure.wrap(self.title, self.width, size, bold=True)
        sub = self.measure.wrap(self.subtitle, self.width, TEXT) if self.subtitle.strip() else []
        height = len(title) * line_height(size) + len(sub) * line_height(TEXT) + (0.06 if sub else 0.0)

        def draw(fig, top):
            write(fig, SIDE, top, "\n".join(title), size, bold=True, gid="title")
            if sub:
                write(fig, SIDE, top - len(title) * line_height(size) - 0.06, "\n".join(sub), TEXT, colour="0.15",
                      gid="subtitle")
        return Block(height, draw, gap=0.14)

    def data_block(self) -> Block:
        """The data table (quantity, value, unit), headed "Data"; split between rows over pages."""
        value = max([self.measure.width(v, TABLE) for _, v, _ in self.data] + [self.measure.width("value", TABLE,
                                                                                                   True)])
        unit = max([self.measure.width(u, TABLE) for _, _, u in self.data] + [self.measure.width("unit", TABLE, True)])
        value, unit = min(value + 0.3, self.width / 5), min(unit + 0.3, self.width / 6)
        columns = [("quantity", "data-label", None, False), ("value", "data-value", value, False),
                   ("unit", "data-unit", unit, False)]
        return table_block(self.measure, self.width, columns, self.data, heading="Data")

    def tasks_block(self, tasks: Sequence[str] | None = None, first: int = 1) -> Block:
        """The numbered tasks, headed "Tasks"; split between tasks over pages."""
        tasks = self.tasks if tasks is None else list(tasks)
        indent = self.measure.width(f"{len(self.tasks)}. ", TEXT) + 0.04
        items = [self.measure.wrap(t, self.width - indent, TEXT) for t in tasks]
        heights = [len(lines) * line_height(TEXT) + 0.05 for lines in items]
        head = line_height(HEADING) + 0.06

        def draw(fig, top):
            write(fig, SIDE, top, "Tasks" if first == 1 else "Tasks (continued)", HEADING, bold=True, gid="heading")
            y = top - head
            for k, (lines, h) in enumerate(zip(items, heights, strict=True), start=first):
                write(fig, SIDE + indent - 0.04, y, f"{k}.", TEXT, ha="right")
                write(fig, SIDE + indent, y, "\n".join(lines), TEXT, gid="task")
                y -= h

        def split(room: float):
            fits = max((k for k in range(len(items) + 1) if head + sum(heights[:k]) <= room), default=0)
            if fits == 0:
                return None, block
            if fits == len(items):
                return block, None
            return self.tasks_block(tasks[:fits], first), self.tasks_block(tasks[fits:], first + fits)

        block = Block(head + sum(heights) - 0.05, draw, split=split)      # no space under the last task
        return block


# ----------------------------------------------------------------------------------------------
# the drawing on the sheet
# ----------------------------------------------------------------------------------------------


@dataclass
class _Drawing:
    """The mechanism at one position and the bounds of what is drawn of it, m."""

    motion: Any
    index: int
    trajectories: list[str]
    bounds: tuple[float, float, float, float]      # xmin, xmax, ymin, ymax of every line and symbol
    scene: Any
    geometry: Any

    @property
    def extent(self) -> tuple[float, float]:
        """Width and height of what is drawn, m."""
        x0, x1, y0, y1 = self.bounds
        return x1 - x0, y1 - y0


def _prepare_drawing(mech: Mechanism, position: int) -> _Drawing:
    motion = table_motion(mech)
    n = len(motion.phi)
    if not isinstance(position, (int, np.integer)) or isinstance(position, bool) or not 0 <= position < n:
        raise InputError(f"mechanism '{mech.name}': position must be an index of its table of {n} positions "
                         f"(0 is position 1, {n - 1} position {n}), got {position!r}")
    point = mech.output_point
    trajectories = [point] if point else []
    geometry = Geometry(motion, [int(position)], trajectories)
    scene = geometry.scene(int(position))
    return _Drawing(motion, int(position), trajectories, _drawn_bounds(motion, int(position), trajectories),
                    scene, geometry)


def _drawn_bounds(motion, index: int, trajectories: list[str]) -> tuple[float, float, float, float]:
    """The data bounds (m) of every line and symbol ``draw_mechanism`` draws, from a draft without
    labels on a figure of its own."""
    ax = new_page().add_axes((0.1, 0.1, 0.8, 0.8))
    draw_mechanism(motion, index, ax, labels=False, trajectories=trajectories, caption=False)
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    return float(x0), float(x1), float(y0), float(y1)


#: room around the drawing inside its axes, inches on paper (for the point labels)
PAPER_MARGIN = 0.3


def _fit_scale(drawing: _Drawing, box_width: float, box_height: float) -> tuple[float, float]:
    """The largest standard scale at which the drawing and its margins fit the box (inches)."""
    room = (max(box_width - 2 * PAPER_MARGIN, 0.1), max(box_height - 2 * PAPER_MARGIN, 0.1))
    extent = tuple(max(e, 1e-9 * max(drawing.extent)) for e in drawing.extent)
    return standard_scale(extent, room)


def _input_word(mech: Mechanism) -> str:
    return "input link" if mech.input_range is not None else "crank"


def _drawing_caption(drawing: _Drawing) -> str:
    mech, motion, i = drawing.motion.mechanism, drawing.motion, drawing.index
    angle = float(np.mod(np.degrees(motion.phi[i]), 360.0))
    angle = 0.0 if angle >= 359.95 else angle
    sense = "counter-clockwise" if motion.direction > 0 else "clockwise"
    who = _input_word(mech)
    text = f"{position_head(motion, i)}: the {who} at φ = {angle:.1f}° from the x axis"
    if mech.input_range is not None:
        a, b = (float(np.degrees(v)) for v in mech.input_range)
        text += f"; it swings between {a:.4g}° and {b:.4g}°, the table runs {sense} from {a:.4g}° (the arrow)"
    elif _rotation(mech) is not None:
        text += f"; it turns {sense} (the arrow)"
    else:
        text += f"; the table follows it {sense} (the arrow; the scheme declares no speed)"
    if drawing.trajectories:
        over = "over the input range" if mech.input_range is not None else "over a turn"
        text += f". Dashed: the path of {', '.join(drawing.trajectories)} {over}"
    return text + "."


def _axes_rect(drawing: _Drawing, scale: tuple[float, float], box_width: float, min_height: float,
               ) -> tuple[float, float, tuple[float, float, float, float]]:
    """Width and height of the axes on paper (inches) and their limits (m) at ``scale``: the axes
    as wide as the box, as high as the drawing and its margins (at least ``min_height``), the
    drawing centred; 1 m is exactly ``paper / real / 0.0254`` inches both ways."""
    inches_per_m = scale[0] / scale[1] / 0.0254
    x0, x1, y0, y1 = drawing.bounds
    height = max((y1 - y0) * inches_per_m + 2 * PAPER_MARGIN, min_height)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    half_w, half_h = box_width / inches_per_m / 2, height / inches_per_m / 2
    return box_width, height, (cx - half_w, cx + half_w, cy - half_h, cy + half_h)


def _drawing_block(sheet: _Sheet, drawing: _Drawing, scale: tuple[float, float]) -> Block:
    """The drawing at ``scale`` with its heading, caption and the 100 mm check bar."""
    width, height, limits = _axes_rect(drawing, scale, _box_width(sheet), MIN_AXES)
    heading = f"The mechanism to scale {scale_text(scale)}"
    caption = _caption_lines(sheet, drawing)
    top_part = line_height(HEADING) + 0.04 + len(caption) * line_height(TABLE) + 0.04

    def draw(fig, top):
        write(fig, SIDE, top, heading, HEADING, bold=True, gid="scale")
        write(fig, SIDE, top - line_height(HEADING) - 0.04, "\n".join(caption), TABLE, gid="caption")
        axes_top = top - top_part - AXES_ABOVE
        _draw_axes(fig, drawing, limits, (SIDE + AXES_LEFT, axes_top - height, width, height))
        _check_bar(fig, axes_top - height - AXES_BELOW - 0.12)

    return Block(_drawing_overhead(sheet, drawing) + height, draw)


def _box_width(sheet: _Sheet) -> float:
    """Width of the drawing's axes, inches: the text's width less the tick labels'."""
    return sheet.width - AXES_LEFT - AXES_RIGHT


def _caption_lines(sheet: _Sheet, drawing: _Drawing) -> list[str]:
    return sheet.measure.wrap(_drawing_caption(drawing), sheet.width, TABLE)


def _drawing_overhead(sheet: _Sheet, drawing: _Drawing) -> float:
    """Height of the drawing's block without its axes, inches: heading, caption, tick labels, bar."""
    return line_height(HEADING) + 0.04 + len(_caption_lines(sheet, drawing)) * line_height(TABLE) + 0.04 + AXES_ABOVE \
        + AXES_BELOW + BAR


def _draw_axes(fig, drawing: _Drawing, limits, rect_in: tuple[float, float, float, float]):
    """The drawing's axes at ``rect_in`` = (left, bottom, width, height), inches, with ``limits``."""
    w, h = fig.get_size_inches()
    left, bottom, width, height = rect_in
    ax = fig.add_axes((left / w, bottom / h, width / w, height / h), label="drawing")
    draw_mechanism(drawing.motion, drawing.index, ax, trajectories=drawing.trajectories, limits=limits, caption=False)
    _rotation_arrow(ax, drawing)
    return ax


def _check_bar(fig, y: float) -> None:
    """A 100 mm bar, ticks every 10 mm, and what it is for, on one line whose middle is at ``y``
    inches."""
    from matplotlib.lines import Line2D

    w, h = fig.get_size_inches()
    x0, x1 = SIDE, SIDE + 100 * MM
    fig.add_artist(Line2D([x0 / w, x1 / w], [y / h, y / h], lw=1.0, color="black", gid="check-bar"))
    for k in range(11):
        x = x0 + 10 * k * MM
        tick = 0.07 if k % 5 == 0 else 0.04
        fig.add_artist(Line2D([x / w, x / w], [(y - tick / 2) / h, (y + tick / 2) / h], lw=0.8, color="black"))
    write(fig, x1 + 0.1, y, "100 mm when printed at 100 % (actual size)", FOOT,
           va="center_baseline", colour="0.25", gid="check-bar-note")


def _input_pivot(mech: Mechanism, scene) -> tuple[np.ndarray, np.ndarray] | None:
    """The input link's pivot on the frame and its farthest other point at the drawn position."""
    link = mech.inputs[0]
    for pair in mech.pairs.values():
        if not isinstance(pair, Prismatic) and set(pair.links) == {mech.frame, link} and pair.point in scene.points:
            pivot = scene.points[pair.point]
            others = [scene.points[p] for p in mech.links[link].points if p in scene.points and p != pair.point]
            if not others:
                return None
            far = max(others, key=lambda q: float(np.hypot(*(q - pivot))))
            return pivot, far
    return None


def _scene_segments(drawing: _Drawing) -> np.ndarray:
    """The lines of the drawn scene as segments ``(M, 4)``, m (for keeping the arrow clear)."""
    sc, u = drawing.scene, drawing.geometry.unit
    lines = [np.vstack([poly, poly[:1]]) if len(poly) >= 3 else poly for _, poly in sc.bodies]
    lines += [line for _, line in sc.slots]
    for line, side in sc.rails:
        surface, _ = rail_hatch(line, side, u)
        lines += [line, surface]
    for p, direction in sc.pivots:
        tri, ground, _ = support(p, direction, u)
        lines += [np.vstack([tri, tri[:1]]), ground]
    lines += [curve for _, _, curve in sc.trajectories]
    segs = [np.hstack([ln[:-1], ln[1:]]) for ln in lines if len(ln) >= 2]
    segs = np.vstack(segs) if segs else np.zeros((0, 4))
    return segs[np.all(np.isfinite(segs), axis=1)]


def _distance_to_segments(points: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """Distance of each point ``(N, 2)`` to the nearest segment of ``segs`` ``(M, 4)``: ``(N,)``."""
    if not len(segs):
        return np.full(len(points), np.inf)
    a, b = segs[None, :, :2], segs[None, :, 2:]
    p = points[:, None, :]
    ab = b - a
    t = np.clip(np.sum((p - a) * ab, axis=2) / np.maximum(np.sum(ab * ab, axis=2), 1e-300), 0.0, 1.0)
    nearest = a + t[..., None] * ab
    return np.min(np.hypot(*(p - nearest).transpose(2, 0, 1)), axis=1)


def _label_boxes(ax) -> np.ndarray:
    """The point labels' boxes in data coordinates, ``(K, 4)``: xmin, ymin, xmax, ymax."""
    renderer = ax.figure.canvas.get_renderer()
    inverse = ax.transData.inverted()
    boxes = []
    for text in ax.texts:
        if str(text.get_gid() or "").startswith("label:"):
            bb = text.get_window_extent(renderer)
            (x0, y0), (x1, y1) = inverse.transform([[bb.x0, bb.y0], [bb.x1, bb.y1]])
            boxes.append((x0, y0, x1, y1))
    return np.array(boxes, dtype=float).reshape(-1, 4)


def _rotation_arrow(ax, drawing: _Drawing) -> None:
    """A curved arrow around the input link's pivot in the sense the table follows it (the sense of
    rotation), on the side where it crosses the fewest lines and labels."""
    from matplotlib.patches import FancyArrowPatch
    from matplotlib.path import Path

    mech = drawing.motion.mechanism
    rotation = drawing.motion.direction
    found = _input_pivot(mech, drawing.scene)
    if found is None:
        return
    pivot, far = found
    length, u = float(np.hypot(*(far - pivot))), drawing.geometry.unit
    radius = min(max(0.55 * length, 3.2 * u), 0.9 * length, 6 * u)   # clear of the pivot's support (2.6 u)
    span = np.radians(110.0)
    centres = np.radians(np.arange(0.0, 360.0, 10.0))
    t = np.linspace(-0.5, 0.5, 41)
    angles = centres[:, None] + span * t[None, :]                       # (C, 41)
    pts = pivot + radius * np.stack([np.cos(angles), np.sin(angles)], axis=2)   # (C, 41, 2)
    clear = 0.6 * drawing.geometry.unit
    near_lines = _distance_to_segments(pts.reshape(-1, 2), _scene_segments(drawing)).reshape(angles.shape) < clear
    boxes = _label_boxes(ax)
    flat = pts.reshape(-1, 2)
    in_label = np.zeros(len(flat), bool)
    for x0, y0, x1, y1 in boxes:
        in_label |= (flat[:, 0] > x0 - clear) & (flat[:, 0] < x1 + clear) & \
                    (flat[:, 1] > y0 - clear) & (flat[:, 1] < y1 + clear)
    x_lo, x_hi = ax.get_xlim()
    y_lo, y_hi = ax.get_ylim()
    outside = (flat[:, 0] < x_lo) | (flat[:, 0] > x_hi) | (flat[:, 1] < y_lo) | (flat[:, 1] > y_hi)
    in_body = np.zeros(len(flat), bool)
    for _, poly in drawing.scene.bodies:
        if len(poly) >= 3:
            in_body |= Path(poly).contains_points(flat)
    cost = near_lines.sum(axis=1) + 3 * in_label.reshape(angles.shape).sum(axis=1) \
        + in_body.reshape(angles.shape).sum(axis=1) + 100 * outside.reshape(angles.shape).sum(axis=1)
    cost = cost + 1e-3 * np.abs(np.mod(centres - np.pi / 2 + np.pi, 2 * np.pi) - np.pi)   # ties: above
    best = angles[int(np.argmin(cost))]
    arc = best if rotation > 0 else best[::-1]
    path = pivot + radius * np.stack([np.cos(arc), np.sin(arc)], axis=1)
    ax.add_patch(FancyArrowPatch(path=Path(path), arrowstyle="-|>,head_length=0.5,head_width=0.25",
                                 mutation_scale=14, lw=1.3, color="black", zorder=11, gid="rotation-arrow",
                                 shrinkA=0, shrinkB=0))



# ----------------------------------------------------------------------------------------------
# the assignment sheet
# ----------------------------------------------------------------------------------------------


def _checked_sheet_input(title, data, tasks, subtitle) -> tuple[list[tuple[str, str, str]], list[str]]:
    if not isinstance(title, str) or not title.strip():
        raise InputError(f"the sheet's title must be a non-empty string, got {title!r}")
    if not isinstance(subtitle, str):
        raise InputError(f"the sheet's subtitle must be a string, got {subtitle!r}")
    rows = []
    for k, row in enumerate(data, start=1):
        if isinstance(row, str) or len(row) != 3 or not all(isinstance(c, str) for c in row):
            raise InputError(f"data row {k} must be three strings (label, value, unit), got {row!r}")
        rows.append(tuple(row))
    if isinstance(tasks, str) or not all(isinstance(t, str) and t.strip() for t in tasks):
        raise InputError(f"tasks must be a sequence of non-empty strings, got {tasks!r}")
    return rows, list(tasks)


def _composed(sheet: _Sheet, drawing: _Drawing, head: list[Block], body: list[Block], numbered: bool) -> list:
    """The pages: ``head`` and the drawing on page 1, at the largest standard scale that fits the
    room page 1 leaves under ``head``; then ``body``, block after block, on as many pages as it
    needs (:func:`~linkage.course.typesetting.paginate`); a footer with the title (and "page k of
    n" when ``numbered``)."""
    usable = A4[1] - TOP - BOTTOM - 0.1 - _drawing_overhead(sheet, drawing)
    room = usable - sum(b.height + b.gap for b in head)
    scale = _fit_scale(drawing, _box_width(sheet), max(room, MIN_AXES))
    continued = _Sheet(sheet.measure, f"{sheet.title} (continued)", "", [], [])
    pages = paginate([*head, _drawing_block(sheet, drawing, scale)], body,
                     lambda: [continued.title_block(HEADING)])
    figures = []
    for k, blocks in enumerate(pages, start=1):
        figures.append(new_page())
        flow(figures[-1], blocks, A4[1] - TOP)
        footer(figures[-1], sheet.measure, sheet.title, f"page {k} of {len(pages)}" if numbered else "")
    return figures


def sheet_figures(mechanism: Mechanism, *, title: str, data: Sequence[tuple[str, str, str]],
                  tasks: Sequence[str], subtitle: str = "", position: int = 0) -> list:
    """The pages of :func:`assignment_sheet` as A4 matplotlib figures.

    The drawing's axes are the figure's axes labelled ``"drawing"``; the scale is the text whose
    gid is ``"scale"``. Each figure has an Agg canvas of its own: ``fig.savefig("page.png")``.
    """
    rows, task_list = _checked_sheet_input(title, data, tasks, subtitle)
    with page_style():
        sheet = _Sheet(Measure(), title, subtitle, rows, task_list)
        drawing = _prepare_drawing(mechanism, position)
        body = ([sheet.data_block()] if rows else []) + ([sheet.tasks_block()] if task_list else [])
        return _composed(sheet, drawing, [sheet.title_block()], body, numbered=False)


def assignment_sheet(mechanism: Mechanism, *, title: str, data: Sequence[tuple[str, str, str]],
                     tasks: Sequence[str], subtitle: str = "", position: int = 0) -> bytes:
    """One variant's assignment sheet: an A4 portrait PDF.

    Page 1 holds the title and subtitle and the mechanism drawn to the largest standard scale that
    fits the rest of the page (the scale written above it, "The mechanism to scale 1:4") at a
    position of its declared table (the scheme's [dynamics] positions, start and sense of
    rotation, as ``linkage analyze`` tabulates them), with a curved arrow for the input's sense of
    rotation, the output point's path dashed, a caption in words and a 100 mm bar to check the
    print; then the data table and the numbered tasks, under the drawing when they fit, else on
    the pages after it (a table or a list of tasks longer than a page is split over pages); the
    title as a footer. :func:`assignment_sheet_from_given` makes a variant's whole sheet from its
    ``given.json``.

    Parameters
    ----------
    mechanism : Mechanism
        The variant (``Template.mechanism(free)``, or any scheme).
    title : str
        ``"Assignment 7 — press_slider_crank"``; also the footer and the PDF's title.
    data : sequence of (label, value, unit)
        The rows of the data table, as text (``("crank length OA", "0.085", "m")``).
    tasks : sequence of str
        What to compute, numbered 1, 2, ... on the sheet.
    subtitle : str
        The mechanism in words (the template's description).
    position : int
        Index of the drawn position in the table (0: position 1).

    Returns
    -------
    bytes
        The PDF; the same bytes for the same input (see the module's docstring).

    Raises
    ------
    InputError
        A position outside the table or not assembled; a title, row or task that is not text.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pages = sheet_figures(mechanism, title=title, data=data, tasks=tasks, subtitle=subtitle, position=position)
    with page_style():
        return pdf_bytes(pages, title)


# ----------------------------------------------------------------------------------------------
# the sheet of a variant, from its given.json
# ----------------------------------------------------------------------------------------------

#: the fields a student fills in, and their shares of the line
STUDENT_FIELDS = (("Student", 2.0), ("Group", 1.0), ("Date", 1.0))
#: space between two fields, inches
FIELD_GAP = 0.3


def _title_block(sheet: _Sheet, given: Mapping[str, Any]) -> Block:
    """The title with the variant (beside it when there is room, else under it) and the student's
    fields to fill in."""
    m = sheet.measure
    variant = (f"Variant {given.get('variant', '')} · folder {given.get('folder', '')} · "
               f"template {given.get('template', '')}")
    beside = m.width(sheet.title, TITLE, True) + 0.3 + m.width(variant, TEXT) <= sheet.width
    title = m.wrap(sheet.title, sheet.width, TITLE, bold=True)
    labels = [m.width(f"{name}: ", TEXT, True) for name, _ in STUDENT_FIELDS]
    room = sheet.width - sum(labels) - FIELD_GAP * (len(STUDENT_FIELDS) - 1)
    share = sum(w for _, w in STUDENT_FIELDS)
    fields = 0.34
    height = len(title) * line_height(TITLE) + (0.0 if beside else line_height(TEXT) + 0.02) + fields

    def draw(fig, top):
        write(fig, SIDE, top, "\n".join(title), TITLE, bold=True, gid="title")
        y = top - len(title) * line_height(TITLE)
        if beside:
            write(fig, SIDE + sheet.width, top - (TITLE - TEXT) / 72, variant, TEXT, colour="0.25", ha="right",
                  gid="variant")
        else:
            write(fig, SIDE, y - 0.02, variant, TEXT, colour="0.25", gid="variant")
            y -= line_height(TEXT) + 0.02
        y -= fields - 0.08
        x = SIDE
        for (name, weight), label in zip(STUDENT_FIELDS, labels, strict=True):
            write(fig, x, y, f"{name}:", TEXT, bold=True, va="baseline", gid="student-field")
            length = room * weight / share
            rule(fig, x + label, x + label + length, y - 0.04, lw=0.7, colour="0.2")
            x += label + length + FIELD_GAP
    return Block(height, draw, gap=0.16)


def _description_block(sheet: _Sheet) -> Block:
    """The mechanism in words (the template's description), under the drawing."""
    lines = sheet.measure.wrap(sheet.subtitle, sheet.width, TEXT)

    def draw(fig, top):
        write(fig, SIDE, top, "\n".join(lines), TEXT, colour="0.15", gid="subtitle")
    return Block(len(lines) * line_height(TEXT), draw, gap=0.16)


def _data_table(sheet: _Sheet, sections: Sequence[tuple[str, Sequence[Mapping[str, str]]]]) -> Block:
    """The data table: quantity, symbol, value, unit, in sections; split between rows over pages."""
    m = sheet.measure
    rows = [r for _, part in sections for r in part]
    symbol = max([m.width(r["symbol"], TABLE, math=True) for r in rows] + [m.width("symbol", TABLE, True)]) + 0.2
    value = min(max([m.width(r["value"], TABLE) for r in rows] + [m.width("value", TABLE, True)]) + 0.2,
                sheet.width * 0.36)
    unit = max([m.width(r["unit"], TABLE) for r in rows] + [m.width("unit", TABLE, True)]) + 0.2
    columns = [("quantity", "data-label", None, False), ("symbol", "data-symbol", symbol, True),
               ("value", "data-value", value, False), ("unit", "data-unit", unit, False)]
    cells: list[tuple[str, ...]] = []
    for title, part in sections:
        cells.append((title,))
        cells += [(r["quantity"], r["symbol"], r["value"], r["unit"]) for r in part]
    return table_block(m, sheet.width, columns, cells, heading="Data", breakable=True)


def _diagrams_heading(sheet: _Sheet, first: Block) -> Block:
    """The heading of the load diagrams, kept on the page of the first diagram."""
    def draw(fig, top):
        write(fig, SIDE, top, "Load diagrams", HEADING, bold=True, gid="heading")
        first.draw(fig, top - line_height(HEADING) - 0.1)
    return Block(line_height(HEADING) + 0.1 + first.height, draw, first.gap)


def given_sheet_figures(given: Mapping[str, Any], position: int = 0) -> list:
    """The pages of :func:`assignment_sheet_from_given` as A4 matplotlib figures."""
    title = str(given.get("title") or f"Assignment {given.get('variant', '')}")
    rows, tasks = _checked_sheet_input(title, [], given.get("tasks", []), str(given.get("description", "")))
    mech = scheme_from_given(given)
    with page_style():
        sheet = _Sheet(Measure(), title, str(given.get("description", "")), rows, tasks)
        drawing = _prepare_drawing(mech, position)
        body = [_description_block(sheet)] if sheet.subtitle.strip() else []
        body += [sheet.tasks_block()] if tasks else []
        grouped: dict[str, list] = {}
        for row in sheet_rows(given):
            if row["kind"] != "diagram":
                grouped.setdefault(row["section"], []).append(row)
        if grouped:
            body.append(_data_table(sheet, list(grouped.items())))
        diagrams = [diagram_block(sheet.measure, sheet.width, d) for d in given.get("diagrams", [])]
        if diagrams:
            body += [_diagrams_heading(sheet, diagrams[0]), *diagrams[1:]]
        return _composed(sheet, drawing, [_title_block(sheet, given)], body, numbered=True)


def assignment_sheet_from_given(given: Mapping[str, Any], position: int = 0) -> bytes:
    """A variant's assignment sheet (A4 PDF), rendered from its ``given.json`` alone.

    Page 1: the title, the variant and its folder, empty fields for the student's name, group and
    date, and the mechanism rebuilt from ``given["scheme"]``
    (:func:`~linkage.course.given.scheme_from_given`) drawn at the largest standard scale that
    fits the rest of the page (:func:`assignment_sheet` says how); then the mechanism in words
    (the template's description), the tasks, the parameters
    of the variant and every section of ``given["data"]`` (quantity, symbol, value, unit: every
    datum the answer key depends on), each load diagram of ``given["diagrams"]`` as a graph over
    the stroke with its zones and its table of values (:func:`~linkage.course.diagram_blocks.diagram_block`)
    after the loads, on as many pages as they need, numbered "page k of n".

    Parameters
    ----------
    given : mapping
        ``given.json`` as data (:func:`linkage.course.given.given_data`).
    position : int
        Index of the drawn position in the table (0: position 1).

    Raises
    ------
    InputError
        ``given`` holds no scheme, or a position outside the table.
    SchemeError
        Its scheme is invalid.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pages = given_sheet_figures(given, position)
    with page_style():
        return pdf_bytes(pages, str(given.get("title") or "Assignment"))
