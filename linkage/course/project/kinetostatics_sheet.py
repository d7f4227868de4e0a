"""The kinetostatics sheet of a course project: each Assur group drawn apart with its loads and
reactions, the force polygons, Zhukovsky's lever and the check of the balancing moment.

The layout (docs/sheets.md) is in proportion to the paper: A1's text is 5 mm (headings) and
3.5 mm, A2's and A3's 3.5 and 2.5 mm, and the room around the drawings scales with the paper's
width. On the left, one row per Assur group in the order they are solved (from the farthest): the
group drawn apart at the sheet's ``μ_l`` with its applied forces, gravity, inertia forces, inertia
and applied moments (curved arrows with their values) and the reactions of its outer pairs, and
its force polygon beside it at the sheet's one ``μ_F``. On the right: the input link drawn apart
with ``M_b`` and its polygon; Zhukovsky's lever (the velocity plan turned 90° clockwise at
``μ_v``, the forces at the images of their points). Along the bottom, beside and above the title
block, packed in columns as low as they go: the polygons' tables (every vector's length and
value), the lever's table of moments, ``M_b`` by the polygons and by the lever with the scales,
and the notes. ``μ_l`` is the largest standard drawing at which every group fits its box (the
largest at most 250 mm on A1); ``μ_F`` draws the longest polygon vector 100–200 mm unless a
polygon must be smaller to fit its box (a note says so); of the arrangements tried, the one
drawing ``μ_l`` and ``μ_F`` least far from their best is kept.

An outer revolute pair of a dyad whose link meets the other link in a revolute pair has its
reaction split as the course does: ``R = Rⁿ + Rτ``, ``Rτ`` across the link from the link's moment
equation about the inner pair, ``Rⁿ`` along the link from the group's polygon, which is drawn in
the student's order (``Rτ`` first, the loads, ``Rⁿ`` closing it) with the whole reactions as
resultants.

Every number comes from :func:`linkage.kinetostatics.plans.build_plans` (the plans, polygons and
lever of ``linkage plans``) at the positions of ``linkage forces``; the split is the only thing
computed here (:mod:`.kinetostatics_parts`). The forces on a group are drawn at ``μ_F`` when they
all fit its box, else as arrows giving their lines and senses, not to scale (the group's heading
says which); the lever's forces are never to scale.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ...kinematics.motion import table_positions_deg
from ...kinetostatics.plans import POLE, ForcePolygon, Plans
from ...model.mechanism import Prismatic, Revolute
from ...report.drawing import Geometry
from ...report.plan_drawings import nice_scale
from .frame import CELL_PAD, TITLE_BLOCK_SIZE, WIDTH_MARGIN, TitleInfo, blank_sheet, scales_table, table
from .kinetostatics_parts import (SUB, DrawnVector, Labels, ReactionSplit, analysis, force_point, global_point, image,
                                  name, num, pair_point, sizes, split_reactions, unit, wrapped)
from .model import Arrow, Circle, Drawing, Line, Scale, Text

__all__ = ["DrawnVector", "ReactionSplit", "KinetostaticsSheet", "compose_kinetostatics", "kinetostatics_sheet",
           "split_reactions"]

#: the lengths below are A1's, mm; a smaller paper's are in proportion to its width (the text
#: heights: :func:`.kinetostatics_parts.sizes`)
#: a polygon vector shorter than this carries no label on the drawing (its table names it), mm
LABELLED_MM = 4.0
#: a force arrow on a group or on the lever when not to scale: the shortest and longest, mm
ARROW_MM = (12.0, 32.0)
#: a polygon whose longest vector is shorter than this at the sheet's μ_F is called small in a note, mm
TINY_MM = 20.0
#: the room kept around a group for its arrows and labels; around a polygon for its labels, mm
GROUP_MARGIN, POLYGON_MARGIN = 36.0, 12.0
#: the largest drawn group; the longest polygon vector's range, mm
GROUP_MM, POLYGON_MM = 250.0, (100.0, 200.0)
#: the heights the input links' band is tried at, fractions of the right column's (the first that draws
#: μ_l and μ_F largest)
INPUT_BAND = (0.30, 0.36, 0.42, 0.5, 0.6)
#: the lever's longest vector below which it is called small, mm
LEVER_MM = 60.0
#: the shares of the left column's width the groups beside their polygons are tried at
GROUP_SHARE = (0.56, 0.62, 0.5)
#: the shares of the right column's width the input link beside its polygon is tried at
INPUT_SHARE = (0.5, 0.62)
#: a force on a group within this angle of a link from its point is drawn ending at the point, degrees
ALONG_DEG = 4.0
#: the radius of a moment's curved arrow, mm
MOMENT_RADIUS = 8.0
#: the gap between the tables and texts packed along the bottom, mm
GAP_MM = 8.0


@dataclass
class KinetostaticsSheet:
    """The sheet and what it draws: ``index`` (0-based) of the table position in
    ``plans.motion``; the scales ``mu_l`` (m/mm), ``mu_f`` (N/mm), ``mu_v`` ((m/s)/mm); every
    polygon vector drawn; the splits; ``M_b`` by the polygons and by the lever, N m."""

    drawing: Drawing
    plans: Plans
    index: int
    mu_l: float
    mu_f: float
    mu_v: float
    vectors: list[DrawnVector] = field(default_factory=list)
    splits: list[ReactionSplit] = field(default_factory=list)
    mb_polygons: float = float("nan")
    mb_lever: float = float("nan")
    notes: list[str] = field(default_factory=list)


def kinetostatics_sheet(mech, position: int, paper: str = "A1", title: TitleInfo = TitleInfo(), *,
                        omega: float | None = None) -> Drawing:
    """The kinetostatics sheet of ``mech`` at table position ``position`` (1-based, as
    ``linkage plans --position``); see :func:`compose_kinetostatics`."""
    return compose_kinetostatics(mech, position, paper, title, omega=omega).drawing


def compose_kinetostatics(mech, position: int, paper: str = "A1", title: TitleInfo = TitleInfo(), *,
                          omega: float | None = None) -> KinetostaticsSheet:
    """Compose the kinetostatics sheet (module docstring) and keep what it draws.

    Parameters
    ----------
    mech : Mechanism
        Driven by a crank, with ``[loads]`` and a speed.
    position : int
        The table position, 1 .. N+1 (the positions of ``linkage forces``).
    paper : str
        ``"A1"``, ``"A2"``, ``"A3"``: the layout and its text heights in proportion to the paper.
    title : TitleInfo
        The title block's names (the scheme's name when ``title.scheme`` is empty).
    omega : float, optional
        The input's angular velocity, rad/s (signed); default ``[dynamics] mean_speed``.

    Raises
    ------
    InputError
        A slide input; no ``[loads]``; no speed; a position outside the table or not assembled.
    """
    plans, i, notes = analysis(mech, position, omega)
    if not title.scheme:
        title = dataclasses.replace(title, scheme=mech.name)
    drawing, free = blank_sheet(paper, title, "Kinetostatic analysis", 2, 3)
    sheet = KinetostaticsSheet(drawing, plans, i, 0.0, 0.0, 0.0, notes=notes)
    _Composer(sheet, free).compose()
    return sheet


def _arrow_mm(value: float, largest: float, k: float) -> float:
    """The (not to scale) length of a force arrow on a group or the lever on a paper ``k`` times
    A1's width, mm."""
    low, high = k * ARROW_MM[0], k * ARROW_MM[1]
    return low + (high - low) * math.sqrt(value / largest) if largest > 0 else low


def _widths(header: list[str], rows: list[list[str]], height: float) -> list[float]:
    """Column widths (mm) a table's texts fit at ``height`` mm."""
    columns = zip(header, *rows)
    return [float(math.ceil(0.7 * WIDTH_MARGIN * height * max(len(line) for t in col for line in t.split("\n"))
                            + 2 * CELL_PAD + 2)) for col in columns]


def _room(box, margin: float, title_room: float) -> tuple[float, float]:
    """The width and height (mm, at least 1) left in ``box`` under its titles (``title_room`` mm),
    ``margin`` mm kept all round."""
    return (max(box[2] - box[0] - 2 * margin, 1.0), max(box[3] - box[1] - 2 * margin - title_room, 1.0))


def _table_height(rows: int, height: float, header: list[str] = ("",)) -> float:
    """The height (mm) of a table of ``header`` (its lines) and ``rows`` rows at text ``height`` mm."""
    lines = max(h.count("\n") + 1 for h in header)
    return (rows + 1) * (2 * height + 1) + 1.6 * height * (lines - 1)


def _pack(blocks: list[tuple[float, float]], spaces: list, gap: float) -> list[tuple[float, float]] | None:
    """The upper left corners (mm) of ``blocks`` (width, height mm) put in order into ``spaces``
    (boxes), in columns from the left, each column from the top; None when they do not all fit."""
    corners: list[tuple[float, float]] = []
    for sx0, sy0, sx1, sy1 in spaces:
        x, y, column = sx0, sy1, 0.0
        while len(corners) < len(blocks):
            w, h = blocks[len(corners)]
            if y - h >= sy0 and x + w <= sx1:
                corners.append((x, y))
                y, column = y - h - gap, max(column, w)
            elif column > 0 and sy1 - h >= sy0 and x + column + gap + w <= sx1:
                x, y, column = x + column + gap, sy1, 0.0
            else:
                break
    return corners if len(corners) == len(blocks) else None


class _Composer:
    def __init__(self, sheet: KinetostaticsSheet, free):
        self.sheet = sheet
        self.d = sheet.drawing
        self.plans = sheet.plans
        self.i = sheet.index
        self.mech = self.plans.motion.mechanism
        self.free = free
        self.labels = Labels(self.d)
        self.s = sizes(self.d)
        self.k = self.s.k
        self.title_room = self.s.heading + 2.6 * self.s.text + 3.0     # a title line and two subtitle lines
        self.margin = GROUP_MARGIN * self.k * (1.0 if self.k > 0.9 else 0.75)  # the room kept around a group
        for item in self.d.items:
            if isinstance(item, Text):
                self.labels.taken(item.box())
        self.inputs = [p for p in self.plans.polygons if p.step.startswith("I(")]
        self.groups = list(reversed([p for p in self.plans.polygons if not p.step.startswith("I(")]))
        self.rows = self.groups + self.inputs                  # as solved: the farthest group first
        self.splits = {p.step: split_reactions(self.plans, p, self.i) for p in self.plans.polygons}
        sheet.splits = [s for p in self.rows for s in self.splits[p.step]]
        self.scene = Geometry(self.plans.motion, [self.i]).scene(self.i)

    # -- layout --------------------------------------------------------------------------------
    def compose(self) -> None:
        x0, y0, x1, y1 = self.free
        top = self._heading((x0 + 5, y1 - 3), x1 - x0 - 10) - 3
        right_w = 0.40 * (x1 - x0)
        gap = GAP_MM * self.k
        # along the bottom, beside and above the title block: the polygons' tables, the lever's
        # table, M_b, the scales and the notes (the notes as the scales chosen below make them)
        bw, bh = TITLE_BLOCK_SIZE
        spaces = lambda band: [(x0 + 4, y0 + 4, x1 - bw - gap / 2, band), (x1 - bw, y0 + bh + gap / 2, x1 - 2, band)]
        height, tables = self._polygon_tables_plan(x1 - x0 - bw - gap)
        lever_table = self._lever_rows()
        lever_h = self._fitting_height(*lever_table, bw)
        notes: list[str] = []
        for _ in range(3):
            blocks = self._bottom_blocks(tables, height, lever_table, lever_h, self.sheet.notes + notes)
            band = max(h for _, h in blocks) + y0 + 4
            while _pack(blocks, spaces(band), gap) is None and band < y0 + 0.7 * (y1 - y0):
                band += 2.0
            area = (x0 + 4, band + gap / 2, x1 - right_w - 4, top)       # the groups, each beside its polygon
            right = (x1 - right_w + 4, band + gap / 2, x1 - 4, top)      # the input links and the lever
            layouts = [self._beside(area, share) for share in GROUP_SHARE]
            if len(self.groups) == 1:
                layouts.insert(0, self._stacked(area))
            column_h = top - right[1]
            candidates = [(groups + self._inputs(right, fraction * column_h, share), fraction * column_h)
                          for fraction in INPUT_BAND for share in INPUT_SHARE for groups in layouts]

            # the lever not small, then μ_l and μ_F the least far from their best
            scales = [self._scales(c[0]) for c in candidates]
            best = np.min(scales, axis=0)
            drawn = [(self._lever_longest() / self._lever_scale((*right[:3], top - input_h - 2)) < LEVER_MM * self.k,
                      float(np.max(np.divide(pair, best))), *pair) for (_, input_h), pair in zip(candidates, scales)]
            boxes, input_h = candidates[min(range(len(candidates)), key=drawn.__getitem__)]
            lever_box = (right[0], right[1], right[2], top - input_h - 2)
            found = self._scale_notes(self._scales(boxes)[1]) + self._lever_notes(self._lever_scale(lever_box))
            if found == notes:
                break
            notes = found
        self.sheet.notes += notes
        self._choose_scales(boxes)
        for polygon, group_box, polygon_box in boxes:
            self._group(polygon, group_box)
            self._polygon(polygon, polygon_box)
        self._lever(lever_box)
        corners = _pack(blocks, spaces(band), gap) or [(x0 + 4, band)] * len(blocks)
        for (x, y), (polygon, (header, _, widths)) in zip(corners, zip(self.rows, tables)):
            caption = self.d.add(Text((x, y), f"Polygon of {polygon.step}", height=self.s.text,
                                      anchor=("left", "top")))
            self.labels.taken(caption.box())
            table(self.d, (x, y - 1.6 * self.s.text - 1), header, self._polygon_rows(polygon, self.mu_f), widths,
                  height=height, name=f"table {polygon.step}")
        self._lever_table(lever_table, corners[len(tables)], lever_h)
        self._checks(*corners[len(tables) + 1:], blocks[-1][0])

    def _bottom_blocks(self, tables, height: float, lever_table, lever_h: float, notes: list[str]) -> list:
        """(width, height) mm of what goes along the bottom: each polygon's table under its caption,
        the lever's table, M_b (its formula and table), the scales, the notes."""
        text = self.s.text
        blocks = [(sum(widths), 1.6 * text + 1 + _table_height(len(rows), height, header))
                  for header, rows, widths in tables]
        blocks.append((sum(_widths(*lever_table, lever_h)), _table_height(len(lever_table[1]), lever_h,
                                                                            lever_table[0])))
        header, rows = self._mb_rows(0.0, 0.0)
        mb_w = max(sum(_widths(header, rows, self.s.tables[0])), 0.7 * text * 32)
        blocks.append((mb_w + self._gap() / 2 + self._scales_width(),
                       max(2.6 * text + 3 + _table_height(2, self.s.tables[0], header),
                           _table_height(3, self.s.tables[0]))))
        notes_w = TITLE_BLOCK_SIZE[0] - 2
        lines = self._notes_text(notes, notes_w).count("\n") + 1
        blocks.append((notes_w, text * (1.6 * lines - 0.6)))
        return blocks

    def _gap(self) -> float:
        return GAP_MM * self.k

    def _scales_width(self) -> float:
        """The scales table's width (:func:`.frame.scales_table`'s rule), mm."""
        height = self.s.tables[0]
        return max(40.0, float(np.ceil(0.7 * WIDTH_MARGIN * height * len("μ_v = 0.0025 (m/s)/mm") + 2 * CELL_PAD + 1)))

    def _heading(self, at, width: float) -> float:
        """The sheet's heading at ``at`` (its upper left corner), in lines of ``width`` mm; returns its lower edge, mm."""
        motion = self.plans.motion
        turned = float(table_positions_deg(motion.phi, motion.direction)[self.i])
        phi = (math.degrees(float(motion.phi[self.i])) + 180.0) % 360.0 - 180.0
        omega = float(motion.omega[self.i])
        text = (f"Kinetostatic analysis of '{self.mech.name}' at position {self.i + 1} of {len(motion.phi) - 1} "
                f"(turned {num(turned)}° from position 1, input angle {num(phi)}°, ω₁ = {num(omega)} rad/s, "
                f"ε₁ = {num(float(motion.eps[self.i]))} rad/s²)")
        text = wrapped(text, 0.7 * WIDTH_MARGIN * self.s.heading, width)
        item = self.d.add(Text(at, text, height=self.s.heading, anchor=("left", "top")))
        self.labels.taken(item.box())
        return item.box()[1]

    def _title(self, box, title: str, subtitle: str) -> None:
        """A box's title (at the text's height when the heading's is too wide) and, under it, its
        subtitle in at most two lines of the box's width."""
        width = box[2] - box[0] - 4
        high = self.s.heading if 0.7 * WIDTH_MARGIN * self.s.heading * len(title) <= width else self.s.text
        subtitle = "\n".join(wrapped(subtitle, 0.7 * WIDTH_MARGIN * self.s.text, width).split("\n")[:2])
        for at, text, h in (((box[0] + 2, box[3] - 1), title, high),
                            ((box[0] + 2, box[3] - 2.5 - self.s.heading), subtitle, self.s.text)):
            item = self.d.add(Text(at, text, height=h, anchor=("left", "top")))
            self.labels.taken(item.box())

    def _inputs(self, right, height: float, share: float) -> list:
        """(input link, its box, its polygon's box) of each input link: side by side in a band of
        ``height`` mm at the top of the right column, the link taking ``share`` of its width."""
        x0, _, x1, top = right
        mid, step = x0 + share * (x1 - x0), height / len(self.inputs)
        return [(polygon, (x0, top - (k + 1) * step + 4, mid - 3, top - k * step),
                 (mid + 3, top - (k + 1) * step + 4, x1, top - k * step)) for k, polygon in enumerate(self.inputs)]

    def _beside(self, area, share: float) -> list:
        """(group, group box, polygon box) of each group, one row each, the polygon right of the group;
        the groups take ``share`` of the width."""
        x0, y0, x1, y1 = area
        row_h = (y1 - y0) / max(len(self.groups), 1)
        split_x = x0 + share * (x1 - x0)
        return [(polygon, (x0, y1 - (k + 1) * row_h + 4, split_x - 3, y1 - k * row_h),
                 (split_x + 3, y1 - (k + 1) * row_h + 4, x1, y1 - k * row_h)) for k, polygon in enumerate(self.groups)]

    def _stacked(self, area) -> list:
        """(group, group box, polygon box) of a lone group: the group above, its polygon below."""
        x0, y0, x1, y1 = area
        split_y = (y0 + y1) / 2
        return [(self.groups[0], (x0, split_y + 3, x1, y1), (x0, y0, x1, split_y - 3))]

    def _scales(self, boxes) -> tuple[float, float]:
        """(μ_l, μ_F): the largest standard drawings at which every group (and input link) fits its box
        with room for its arrows, the largest at most GROUP_MM, and every polygon fits its box, the
        longest vector at most 200 mm."""
        i = self.i
        need = 0.0
        for polygon, box, _ in boxes:
            span = np.ptp(self._link_points(polygon.links), axis=0)
            room = _room(box, self.margin, self.title_room)
            need = max(need, span[0] / room[0], span[1] / room[1], max(span) / (GROUP_MM * self.k))
        mu_l = nice_scale(need)
        longest = max(float(np.hypot(*v.vector[i])) for p in self.plans.polygons for v in p.forces)
        need = longest / POLYGON_MM[1]
        for polygon, _, box in boxes:
            span = np.ptp(self._chain(polygon), axis=0)
            room = _room(box, POLYGON_MARGIN * self.k, self.title_room)
            need = max(need, span[0] / room[0], span[1] / room[1])
        return mu_l, nice_scale(need)

    def _scale_notes(self, mu_f: float) -> list[str]:
        """The notes μ_F (N/mm) calls for: chosen so the polygons fit, a polygon small."""
        i, notes = self.i, []
        longest = max(float(np.hypot(*v.vector[i])) for p in self.plans.polygons for v in p.forces)
        if longest / mu_f < POLYGON_MM[0]:
            notes.append(f"μ_F is chosen so the polygons fit their places: the longest vector is "
                         f"{longest / mu_f:.0f} mm")
        for polygon in self.plans.polygons:
            top = max(float(np.hypot(*v.vector[i])) for v in polygon.forces)
            if top / mu_f < TINY_MM * self.k:
                notes.append(f"the polygon of {polygon.step} is small at μ_F = {num(mu_f)} N/mm (its "
                             f"longest vector {top / mu_f:.1f} mm): its table gives the values")
        return notes

    def _choose_scales(self, boxes) -> None:
        self.mu_l, self.mu_f = self._scales(boxes)
        self.sheet.mu_l, self.sheet.mu_f = self.mu_l, self.mu_f
        self.d.use(Scale("μ_l", self.mu_l, "m/mm"))
        self.d.use(Scale("μ_F", self.mu_f, "N/mm"))

    def _link_points(self, links) -> np.ndarray:
        mech, motion = self.mech, self.plans.motion
        pts = [global_point(motion, k, local, self.i) for k in links for local in mech.links[k].points.values()]
        return np.array(pts).reshape(-1, 2)

    # -- a group drawn apart ---------------------------------------------------------------------
    def _shown_forces(self, polygon: ForcePolygon) -> list[tuple[np.ndarray, np.ndarray, str]]:
        """(point m, vector N, label) of the forces drawn on a group: loads and known reactions as
        they are, the unknown reactions split or whole."""
        splits = {s.label: s for s in self.splits[polygon.step]}
        shown = []
        for f in polygon.forces:
            at = force_point(self.plans, f, self.i)
            if f.label in splits:
                s = splits[f.label]
                shown += [(at, s.normal, name(f.label, "n")), (at, s.tangential, name(f.label, "t"))]
            else:
                shown.append((at, f.vector[self.i], name(f.label)))
        return shown

    def _group(self, polygon: ForcePolygon, box) -> None:
        d, i = self.d, self.i
        pts = self._link_points(polygon.links)
        centre_q = (pts.min(axis=0) + pts.max(axis=0)) / 2
        centre_mm = ((box[0] + box[2]) / 2, (box[1] + box[3] - self.title_room) / 2)
        view = d.view(Scale("μ_l", self.mu_l, "m/mm"), origin=centre_mm, at=tuple(centre_q)).paper
        shown = self._shown_forces(polygon)
        largest = max([float(np.hypot(*v)) for _, v, _ in shown] + [0.0])
        shown = [(np.array(view(at)), v, label) for at, v, label in shown if float(np.hypot(*v)) > 1e-9 * largest]
        links_mm = np.array([view(q) for q in pts])
        inner = (box[0] + 6, box[1] + 6, box[2] - 6, box[3] - self.title_room - 6)
        arrows = self._group_arrows(shown, links_mm, largest, True)
        to_scale = all(inner[0] <= e[0] <= inner[2] and inner[1] <= e[1] <= inner[3]
                       for start, end, *_ in arrows for e in (start, end))
        if not to_scale:
            arrows = self._group_arrows(shown, links_mm, largest, False)
        input_link = polygon.step.startswith("I(")
        self._title(box, f"{'Input link' if input_link else 'Group'} {polygon.step}: "
                    f"link{'s' if len(polygon.links) > 1 else ''} {', '.join(polygon.links)}",
                    f"μ_l = {num(self.mu_l)} m/mm; " + (f"forces at μ_F = {num(self.mu_f)} N/mm" if to_scale else
                                                        "forces not to scale (lines and senses only)"))
        d.region(f"group {polygon.step}", box)
        inside = set(polygon.links)
        pins = []
        sc = self.scene
        for link, hull in sc.bodies:
            if link in inside:
                pts_mm = [view(p) for p in hull]
                d.add(Line(tuple(pts_mm), layer="links", width=0.7, closed=len(hull) > 2))
                self.labels.mark(pts_mm + pts_mm[:1])
        for link, line in sc.slots:
            if link in inside:
                a, b = view(line[0]), view(line[1])
                d.add(Line((a, b), layer="links", width=0.5, dashed=True))
                self.labels.mark([a, b])
        for link, centre, angle, _ in sc.blocks:
            if link in inside:
                self._block(view(centre), angle)
        for pair in self.mech.pairs.values():
            if isinstance(pair, Revolute) and set(pair.links) & inside:
                p = view(pair_point(self.plans.motion, pair.name, next(k for k in pair.links if k in inside), i))
                d.add(Circle(p, 1.8, layer="links", width=0.5))
                self.labels.mark([p])
                pins.append((p, pair.point))
            elif isinstance(pair, Prismatic) and set(pair.links) & inside and not set(pair.links) <= inside:
                if pair.links[0] not in inside:          # the removed guide: its line through the slider
                    centre = pair_point(self.plans.motion, pair.name, pair.links[1], i)
                    u = self._guide_direction(pair)
                    a, b = view(centre - 18 * self.mu_l * u), view(centre + 18 * self.mu_l * u)
                    d.add(Line((a, b), layer="links", width=0.35, dashed=True))
                    self.labels.mark([a, b])
        for start, end, _, _ in arrows:
            d.add(Arrow(tuple(map(float, start)), tuple(map(float, end)), layer="forces", width=0.5, head=3.5))
            self.labels.mark([start, end])
        moments = [(np.array(view(self._moment_point(m))), float(m.value[i]), name(m.label)) for m in polygon.moments
                   if float(m.value[i]) != 0 and np.isfinite(float(m.value[i]))]
        for centre, value, _ in moments:
            self._curved(centre, value)
        for p, label in pins:                           # the labels once every line is drawn
            self.labels.add(p, label, box, height=self.s.text, prefer=(-1, 1), gap=2.5)
        for start, end, far, label in arrows:
            self.labels.add(far, label, box, height=self.s.text, prefer=far - (start + end) / 2)
        for centre, value, label in moments:
            self.labels.add(centre, f"{label} = {num(value)} N·m", box, height=self.s.text, prefer=(0.3, -1),
                            gap=self._radius() + 2.0)

    def _group_arrows(self, shown, links_mm: np.ndarray, largest: float, to_scale: bool) -> list:
        """(start, end, the end away from the point, label) of each force on a group, mm: from its
        point, at μ_F or not to scale; a force that would run along a link from its point is drawn
        ending at the point instead, so the link does not hide it."""
        out = []
        for at, vector, label in shown:
            size = float(np.hypot(*vector))
            u = unit(vector)
            length = size / self.mu_f if to_scale else _arrow_mm(size, largest, self.k)
            towards = links_mm - at
            reach = np.hypot(towards[:, 0], towards[:, 1])
            along = (reach > 1.0) & (towards @ u > np.cos(np.radians(ALONG_DEG)) * reach)
            if along.any():
                out.append((at - length * u, at, at - length * u, label))
            else:
                out.append((at, at + length * u, at + length * u, label))
        return out

    def _moment_point(self, m) -> np.ndarray:
        mech, i = self.mech, self.i
        if m.pair is not None:
            return pair_point(self.plans.motion, m.pair, m.link, i)
        return global_point(self.plans.motion, m.link, mech.links[m.link].center_of_mass, i)

    def _guide_direction(self, pair) -> np.ndarray:
        glink = pair.links[0]
        guide = self.mech.links[glink].guides[pair.guide]
        angle = guide.angle + (0.0 if glink == self.mech.frame else float(self.plans.motion.poses[glink][self.i, 2]))
        return np.array([math.cos(angle), math.sin(angle)])

    def _block(self, c, angle: float) -> None:
        c = np.asarray(c)
        u = np.array([math.cos(angle), math.sin(angle)])
        n = np.array([-u[1], u[0]])
        corners = [c + sx * 8.0 * u + sy * 4.5 * n for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        self.d.add(Line(tuple(tuple(map(float, p)) for p in corners), layer="links", width=0.7, closed=True))
        self.labels.mark(corners + corners[:1])

    def _radius(self) -> float:
        """A moment's curved arrow's radius, mm."""
        return max(MOMENT_RADIUS * self.k, 5.0)

    def _curved(self, centre: np.ndarray, value: float) -> None:
        """A moment: an arc of 240° about ``centre`` (mm), CCW for a positive ``value``, its head at
        the arc's end."""
        sense = 1.0 if value > 0 else -1.0
        angles = np.radians(np.linspace(-30, 210, 31)) if sense > 0 else np.radians(np.linspace(210, -30, 31))
        pts = centre + self._radius() * np.column_stack([np.cos(angles), np.sin(angles)])
        self.d.add(Line(tuple(tuple(map(float, p)) for p in pts[:-1]), layer="forces", width=0.5))
        self.d.add(Arrow(tuple(map(float, pts[-4])), tuple(map(float, pts[-1])), layer="forces", width=0.5, head=3.0))
        self.labels.mark(pts)

    # -- a force polygon -------------------------------------------------------------------------
    def _sequence(self, polygon: ForcePolygon) -> list[tuple[str, str, np.ndarray]]:
        """(label, kind, vector N) head to tail: a dyad's split reactions in the student's order
        (Rτ of the first link, the known forces of both links, Rτ and Rⁿ of the second, its whole
        unknowns, the first link's whole unknowns, Rⁿ of the first), else the polygon's order."""
        i = self.i
        splits = {s.label: s for s in self.splits[polygon.step]}
        if not splits:
            return [(f.label, "force", f.vector[i]) for f in polygon.forces]
        first, second = polygon.links
        own = {k: [f for f in polygon.forces if f.link == k] for k in polygon.links}

        def part(k, which):
            out = []
            for f in own[k]:
                split = splits.get(f.label)
                if which == "rest" and not f.unknown:
                    out.append((f.label, "force", f.vector[i]))
                elif which == "whole" and f.unknown and split is None:
                    out.append((f.label, "force", f.vector[i]))
                elif which in ("tangential", "normal") and split is not None:
                    out.append((f.label, which, getattr(split, which)))
            return out

        return (part(first, "tangential") + part(first, "rest") + part(second, "rest") + part(second, "tangential")
                + part(second, "normal") + part(second, "whole") + part(first, "whole") + part(first, "normal"))

    def _chain(self, polygon: ForcePolygon) -> np.ndarray:
        seq = self._sequence(polygon)
        return np.vstack([np.zeros(2)] + list(np.cumsum([v for _, _, v in seq], axis=0)))

    def _polygon_vectors(self, polygon: ForcePolygon) -> list[tuple[str, str, np.ndarray]]:
        """(label, kind, vector N) of every vector a polygon draws: the head-to-tail sequence, then
        the whole split reactions and the reaction between a dyad's links."""
        out = list(self._sequence(polygon))
        out += [(s.label, "resultant", s.whole) for s in self.splits[polygon.step]]
        if len(polygon.links) == 2 and len(polygon.internal) == 1:
            out.append((polygon.internal[0].label, "internal", polygon.internal[0].vector[self.i]))
        return out

    def _polygon_rows(self, polygon: ForcePolygon, mu: float) -> list[list[str]]:
        rows = []
        for label, kind, vector in self._polygon_vectors(polygon):
            size = float(np.hypot(*vector))
            rows.append([name(label, {"normal": "n", "tangential": "t"}.get(kind, "")), f"{size / mu:.1f}", num(size)])
        return rows + [[f"{name(m.label)}, N·m", "—", num(float(m.value[self.i]))] for m in polygon.moments]

    def _polygon(self, polygon: ForcePolygon, box) -> None:
        d, i, mu = self.d, self.i, self.mu_f
        self._title(box, f"Force polygon of {polygon.step}", f"μ_F = {num(mu)} N/mm")
        d.region(f"polygon {polygon.step}", box)
        seq = self._sequence(polygon)
        chain = self._chain(polygon) / mu
        lo, hi = chain.min(axis=0), chain.max(axis=0)
        origin = np.array([(box[0] + box[2]) / 2, (box[1] + box[3] - self.title_room) / 2]) - (lo + hi) / 2
        centroid = origin + chain.mean(axis=0)
        ends: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        here = origin.copy()
        first_link_end = None
        texts = []
        for label, kind, vector in seq:
            start, end = here, here + vector / mu
            here = end
            ends[f"{kind}:{label}"] = (start, end)
            part = {"normal": "n", "tangential": "t"}.get(kind, "")
            texts.append(self._vector(polygon.step, label, kind, start, end, vector, name(label, part),
                                      width=0.6 if kind == "force" else 0.45))
            f = next((f for f in polygon.forces if f.label == label), None)
            if f is not None and len(polygon.links) == 2 and f.link == polygon.links[0] and kind != "normal" \
                    and (kind != "force" or not f.unknown):
                first_link_end = end
        for s in self.splits[polygon.step]:            # the whole reaction: Rⁿ + Rτ
            n_start, n_end = ends[f"normal:{s.label}"]
            t_start, t_end = ends[f"tangential:{s.label}"]
            start, end = (n_start, t_end) if np.allclose(n_end, t_start) else (t_start, n_end)
            texts.append(self._vector(polygon.step, s.label, "resultant", start, end, s.whole, name(s.label),
                                      width=0.35))
        if len(polygon.links) == 2 and len(polygon.internal) == 1 and first_link_end is not None:
            inner = polygon.internal[0]
            texts.append(self._vector(polygon.step, inner.label, "internal", first_link_end,
                                      first_link_end + inner.vector[i] / mu, inner.vector[i], name(inner.label),
                                      width=0.35))
        d.add(Circle(tuple(map(float, origin)), 1.0, layer="forces", filled=True))
        self.labels.mark([origin])
        for mid, text in texts:                         # the labels once every line is drawn
            if mid is not None:
                self.labels.add(mid, text, box, height=self.s.text, prefer=mid - centroid, gap=1.2)

    def _vector(self, step, label, kind, start, end, value, text, width) -> tuple[np.ndarray | None, str]:
        """Draw a polygon vector; returns its midpoint (None when too short to label) and label."""
        start, end = tuple(map(float, start)), tuple(map(float, end))
        length = math.hypot(end[0] - start[0], end[1] - start[1])
        head = min(3.5, 0.4 * length + 0.5)
        if kind in ("resultant", "internal"):          # dashed: the shaft, then the head alone
            u = unit(np.subtract(end, start))
            items = (self.d.add(Line((start, end), layer="forces", width=width, dashed=True)),
                     self.d.add(Arrow(tuple(map(float, np.asarray(end) - min(head, length) * u)), end,
                                      layer="forces", width=width, head=head)))
        else:
            items = (self.d.add(Arrow(start, end, layer="forces", width=width, head=head)),)
        self.sheet.vectors.append(DrawnVector(step, label, kind, start, end, np.asarray(value, float).copy(), items))
        self.labels.mark([start, end])
        return ((np.asarray(start) + np.asarray(end)) / 2 if length >= LABELLED_MM else None), text

    # -- the tables ------------------------------------------------------------------------------
    def _polygon_tables_plan(self, width: float) -> tuple[float, list]:
        """The text height the polygons' tables fit ``width`` mm side by side at, and each table's
        (header, rows, widths); rows sized with lengths at 1 N/mm (the widest they can be)."""
        header = ["force", "length, mm", "value, N"] if self.k > 0.9 else ["force", "length,\nmm", "value,\nN"]
        for height in self.s.tables:
            tables = []
            for polygon in self.rows:
                rows = self._polygon_rows(polygon, 1.0)
                tables.append((header, rows, _widths(header, rows, height)))
            if sum(sum(w) for *_, w in tables) + GAP_MM * self.k * (len(tables) - 1) <= width:
                break
        return height, tables

    def _fitting_height(self, header, rows, width: float) -> float:
        return next((h for h in self.s.tables if sum(_widths(header, rows, h)) <= width), self.s.tables[-1])

    def _lever_rows(self) -> tuple[list[str], list[list[str]]]:
        """The header and rows of the lever's table (the arm ``h`` at ``μ_v``, filled once it is known)."""
        lever, i = self.plans.lever, self.i
        biggest = max([abs(float(f.moment[i])) for f in lever.forces]
                      + [abs(float(m.contribution[i])) for m in lever.moments] + [1e-300])

        def zeroed(x: float) -> str:                    # round-off of a force through the pole reads 0
            return num(x if abs(x) > 1e-12 * biggest else 0.0)

        rows = []
        for f in lever.forces:
            size = float(np.hypot(*f.force[i]))
            arm = abs(float(f.moment[i])) / size if size > 0 else 0.0          # m/s; /μ_v gives mm
            rows.append([f"{name(f.label)} at {image(f.point)}", num(size), arm, zeroed(float(f.moment[i]))])
        for m in lever.moments:
            rows.append([f"{name(m.label)}·ω{m.link.translate(SUB)}", num(float(m.value[i])), "—",
                         zeroed(float(m.contribution[i]))])
        rows = [[r[0], r[1], "000.0" if isinstance(r[2], float) else r[2], r[3]] for r in rows]
        return ["force at\nits image", "F, N", "h, mm", "F·h·μ_v,\nN·m/s"], rows

    def _lever_table(self, header_rows, top_left, height: float) -> None:
        header, rows = header_rows
        lever, i = self.plans.lever, self.i
        for row, f in zip(rows, lever.forces):
            size = float(np.hypot(*f.force[i]))
            row[2] = f"{abs(float(f.moment[i])) / size / self.mu_v:.1f}" if size > 0 else "0.0"
        table(self.d, top_left, header, rows, _widths(header, rows, height), height=height, name="lever table")

    def _mb_rows(self, mb_poly: float, mb_lever: float) -> tuple[list[str], list[list[str]]]:
        """The header and rows of the table comparing ``M_b`` (N m) by the polygons and by the lever."""
        diff = (mb_lever - mb_poly) / abs(mb_poly) * 100.0 if mb_poly != 0 else 0.0
        return (["balancing\nmoment Mb", "Mb, N·m", "difference,\n%"],
                [["by the force polygons", num(mb_poly), ""],
                 ["by Zhukovsky's lever", num(mb_lever), num(round(diff, 3)) if abs(diff) >= 1e-3 else "0.000"]])

    def _notes_text(self, notes: list[str], width: float) -> str:
        """The numbered notes in lines of ``width`` mm under "Notes:"."""
        notes = ["Arrows on the lever show the lines and senses of the forces, not to scale: its table gives "
                 "the values; the polygons are drawn at μ_F."] + notes
        return "Notes:\n" + "\n".join(wrapped(f"{k + 1}. {line}", 0.7 * WIDTH_MARGIN * self.s.text, width)
                                      for k, line in enumerate(notes))

    def _checks(self, at, notes_at, width: float) -> None:
        """``M_b`` by the lever's formula, the table comparing it with the polygons' and right of
        them the scales, at ``at`` (upper left, mm); the notes in lines of ``width`` mm at ``notes_at``."""
        d, i, lever, height = self.d, self.i, self.plans.lever, self.s.tables[0]
        x0, top = at
        total = sum(float(f.moment[i]) for f in lever.forces) + sum(float(m.contribution[i]) for m in lever.moments)
        mb_lever = float(lever.balancing_moment[i])
        mb_poly = float(next(m.value[i] for m in self.inputs[0].moments if m.kind == "balancing"))
        self.sheet.mb_lever, self.sheet.mb_polygons = mb_lever, mb_poly
        formula = d.add(Text((x0, top), f"Mb = −ΣM/ω₁ =\n−({num(total)})/({num(float(lever.omega[i]))}) = "
                             f"{num(mb_lever)} N·m", height=self.s.text, anchor=("left", "top")))
        self.labels.taken(formula.box())
        header, rows = self._mb_rows(mb_poly, mb_lever)
        mb = table(d, (x0, formula.box()[1] - 3), header, rows, _widths(header, rows, height), height=height,
                   name="balancing moment")
        scales_table(d, (max(mb[2], formula.box()[2]) + self._gap() / 2, top), height=height)
        note = d.add(Text(notes_at, self._notes_text(self.sheet.notes, width), height=self.s.text,
                          anchor=("left", "top")))
        self.labels.taken(note.box())

    def _lever_notes(self, mu_v: float) -> list[str]:
        """The note μ_v ((m/s)/mm) calls for: the lever small."""
        longest = self._lever_longest() / mu_v
        return ([f"the lever is small at μ_v = {num(mu_v)} (m/s)/mm: its longest vector is {longest:.0f} mm"]
                if longest < LEVER_MM * self.k else [])

    # -- Zhukovsky's lever -----------------------------------------------------------------------
    def _lever_longest(self) -> float:
        """The velocity plan's longest vector, m/s."""
        return max(float(np.hypot(*v.vector[self.i])) for v in self.plans.velocity.vectors)

    def _lever_scale(self, box) -> float:
        """μ_v, (m/s)/mm: the largest standard drawing the lever fits ``box`` at with room for its arrows."""
        v = self.plans.velocity.images
        pts = np.array([np.zeros(2)] + [[q[self.i, 1], -q[self.i, 0]] for q in v.values()])
        span = np.ptp(pts, axis=0)
        room = _room(box, self.margin, self.title_room)
        return nice_scale(max(span[0] / room[0], span[1] / room[1]))

    def _lever(self, box) -> None:
        d, i, plans = self.d, self.i, self.plans
        lever = plans.lever
        x0, y0, x1, y1 = box
        d.region("lever", box)
        turned = {k: np.array([v[i, 1], -v[i, 0]]) for k, v in plans.velocity.images.items()}
        turned[POLE] = np.zeros(2)
        pts = np.array(list(turned.values()))
        self.mu_v = self.sheet.mu_v = mu_v = self._lever_scale(box)
        self._title(box, "Zhukovsky's lever: the velocity plan turned 90° clockwise",
                    f"μ_v = {num(mu_v)} (m/s)/mm; the forces at the images of their points, not to scale")
        centre_q = (pts.min(axis=0) + pts.max(axis=0)) / 2
        view = d.view(Scale("μ_v", mu_v, "(m/s)/mm"), origin=((x0 + x1) / 2, (y0 + y1 - self.title_room) / 2),
                      at=tuple(centre_q)).paper
        frame_points = {q for q in plans.velocity.images if q in self.mech.point_names
                        and self.mech.point_link(q) == self.mech.frame}
        for link, labels in plans.velocity.links.items():
            fig = [view(turned[q]) for q in labels if q in turned]
            if len(fig) >= 2:
                d.add(Line(tuple(fig), layer="plans", width=0.5, closed=len(fig) > 2))
                self.labels.mark(fig + fig[:1])
        for v in plans.velocity.vectors:
            if v.kind == "absolute":
                a, b = view(turned[POLE]), view(turned[v.end])
                d.add(Line((a, b), layer="plans", width=0.25))
                self.labels.mark([a, b])
        p = view(turned[POLE])
        d.add(Circle(p, 1.0, layer="plans", filled=True))
        self.labels.mark([p])
        largest = max([float(np.hypot(*f.force[i])) for f in lever.forces] + [0.0])
        arrows = []
        for f in lever.forces:
            size = float(np.hypot(*f.force[i]))
            if size <= 1e-9 * largest:
                continue
            start = np.array(view(turned[f.point]))
            end = start + _arrow_mm(size, largest, self.k) * unit(f.force[i])
            d.add(Arrow(tuple(start), tuple(end), layer="forces", width=0.5, head=3.5))
            self.labels.mark([start, end])
            arrows.append((end, name(f.label), unit(f.force[i])))
        self.labels.add(p, "p", box, height=self.s.text, prefer=(-1, -1), gap=1.5)
        for label, q in turned.items():
            if label == POLE or label in frame_points or np.hypot(*q) / mu_v < 0.5:
                continue
            at = view(q)
            d.add(Circle(at, 0.8, layer="plans", filled=True))
            self.labels.add(at, image(label), box, height=self.s.text, prefer=(1, 1), gap=1.5)
        for end, label, direction in arrows:
            self.labels.add(end, label, box, height=self.s.text, prefer=direction)
