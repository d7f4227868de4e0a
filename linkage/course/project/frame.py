"""A sheet's frame, title block, ruled tables and the layout checks of a drawing.

:func:`blank_sheet` starts every sheet: the frame 20 mm from the left edge (binding) and 5 mm
from the others, and the common drafting title block, 185 x 55 mm in the lower right corner
inside the frame (project, scheme, variant, sheet name, "Sheet k of K", student, group, a blank
date column, the paper size). The frame and its title block are the only items on the
``"frame"`` layer; :func:`layout_problems` checks every other item against them. :func:`table`
rules a table with a header over every column; :func:`scales_table` lists the scales a sheet
states.

>>> drawing, free = blank_sheet("A3", TitleInfo(scheme="Crank-slider", variant="7"), "Kinematic analysis", 1, 3)
>>> free
(20.0, 5.0, 415.0, 292.0)
>>> [r.name for r in drawing.regions]
['frame', 'title block']
>>> layout_problems(drawing)
[]
"""

from __future__ import annotations

import itertools
import re
import textwrap
from dataclasses import dataclass

import numpy as np

from .model import Drawing, Line, Text

__all__ = [
    "FRAME_MARGINS",
    "TITLE_BLOCK_SIZE",
    "TitleInfo",
    "blank_sheet",
    "extent",
    "layout_problems",
    "scales_table",
    "table",
]

#: the frame's distance from the paper's edges (left, bottom, right, top), mm
FRAME_MARGINS = (20.0, 5.0, 5.0, 5.0)
#: the title block's width and height, mm
TITLE_BLOCK_SIZE = (185.0, 55.0)
#: line widths of the frame (thick), the title block's main and thin rules, a table's rules, mm
FRAME_WIDTH, MAIN_RULE, THIN_RULE = 1.0, 0.7, 0.25
#: the standard text heights a cell's text is fitted from, largest first, mm
TEXT_HEIGHTS = (5.0, 3.5, 2.5)
#: the clear margin between a cell's rules and its text, mm
CELL_PAD = 0.75
#: a text's width here is its :meth:`Text.box` width times this: the box takes 0.7 of the
#: height per character, DejaVu Sans draws up to 0.81 (capitals, "m", "w")
WIDTH_MARGIN = 0.81 / 0.7
_TOL = 1e-6


@dataclass
class TitleInfo:
    """What the title block names: the project, the scheme, the variant, the student and group;
    ``number`` and ``total``, when given, number the sheet (over :func:`blank_sheet`'s own)."""

    project: str = "Course project: theory of machines and mechanisms"
    scheme: str = ""
    variant: str = ""
    student: str = ""
    group: str = ""
    number: int | None = None
    total: int | None = None


def blank_sheet(paper: str, title: TitleInfo, name: str, number: int,
                total: int) -> tuple[Drawing, tuple[float, float, float, float]]:
    """A sheet with its frame and title block.

    Parameters
    ----------
    paper : str
        ``"A1"``, ``"A2"``, ``"A3"`` or ``"A4"`` (landscape).
    title : TitleInfo
        The names the title block shows.
    name : str
        The sheet's name, e.g. ``"Kinematic analysis"``.
    number, total : int
        The sheet is ``number`` of ``total`` (``1 <= number <= total``); ``title.number`` and
        ``title.total`` stand instead when given.

    Returns
    -------
    drawing : Drawing
        The sheet, with the regions ``"frame"`` (the frame's inner box) and ``"title block"``.
    free : tuple of 4 float
        The frame's inner box ``(x0, y0, x1, y1)``, mm; the title block is its lower right corner.
    """
    number = title.number if title.number is not None else number
    total = title.total if title.total is not None else total
    if not 1 <= number <= total:
        raise ValueError(f"sheet {number} of {total}: the number must be between 1 and the total")
    drawing = Drawing(paper, title=name)
    width, height = drawing.size
    left, bottom, right, top = FRAME_MARGINS
    free = (left, bottom, width - right, height - top)
    drawing.add(Line(_rectangle(free), layer="frame", width=FRAME_WIDTH, closed=True))
    drawing.region("frame", free)
    block = (free[2] - TITLE_BLOCK_SIZE[0], free[1], free[2], free[1] + TITLE_BLOCK_SIZE[1])
    _title_block(drawing, block, title, name, number, total)
    drawing.region("title block", block)
    return drawing, free


def _title_block(drawing: Drawing, block, title: TitleInfo, name: str, number: int, total: int) -> None:
    """The 185 x 55 mm block: on the left 65 mm a ruled list of signatures (5 mm rows: five
    change rows, a header row, Student/Checked/Approved rows with a blank date column; a name
    longer than its 27 mm cell (12 characters) holds at 2.5 mm is shortened with an ellipsis); on the
    right 120 mm the project (15 mm band), the sheet's and scheme's names beside the variant,
    paper and sheet number cells, and the group."""
    x0, y0, x1, y1 = block
    rule = _Ruler(drawing, x0, y0)
    drawing.add(Line(_rectangle(block), layer="frame", width=MAIN_RULE, closed=True))
    # left part: columns 18 | 27 | 10 | 10 mm, eleven rows of 5 mm (five change rows above the header)
    for k in range(1, 11):
        rule.h(0, 65, 5 * k, MAIN_RULE if k in (5, 6) else THIN_RULE)
    rule.v(65, 0, 55, MAIN_RULE)
    for x in (18, 45, 55):
        rule.v(x, 0, 55, MAIN_RULE)
    for label, x, w in (("Rev.", 0, 18), ("Name", 18, 27), ("Sign", 45, 10), ("Date", 55, 10)):
        _cell_text(drawing, (x0 + x, y0 + 25, x0 + x + w, y0 + 30), label, heights=(2.5,))
    roles = (("Student", title.student), ("Checked", ""), ("", ""), ("", ""), ("Approved", ""))
    for row, (role, person) in enumerate(roles):
        ytop = 25 - 5 * row
        if role:
            _cell_text(drawing, (x0, y0 + ytop - 5, x0 + 18, y0 + ytop), role, heights=(2.5,), align="left")
        if person:
            _cell_text(drawing, (x0 + 18, y0 + ytop - 5, x0 + 45, y0 + ytop), person, heights=(2.5,),
                       align="left")
    # right part: the project band 15 mm, the name cell 70 x 25 mm, the cells 50 x 25, the group 50 x 15
    rule.h(65, 185, 40, MAIN_RULE)
    rule.h(65, 185, 15, MAIN_RULE)
    rule.v(135, 0, 40, MAIN_RULE)
    rule.h(135, 185, 35, MAIN_RULE)
    rule.h(135, 185, 20, MAIN_RULE)
    rule.v(160, 20, 40, MAIN_RULE)
    _cell_text(drawing, (x0 + 65, y0 + 40, x1, y1), title.project, heights=(5.0, 3.5))
    _cell_text(drawing, (x0 + 65, y0 + 15, x0 + 135, y0 + 40), name, heights=(5.0, 3.5))
    scheme = f"Scheme: {title.scheme}" if title.scheme else "Scheme:"
    _cell_text(drawing, (x0 + 65, y0, x0 + 135, y0 + 15), scheme, heights=(3.5, 2.5))
    _cell_text(drawing, (x0 + 135, y0 + 35, x0 + 160, y0 + 40), "Variant", heights=(2.5,))
    _cell_text(drawing, (x0 + 160, y0 + 35, x1, y0 + 40), "Paper", heights=(2.5,))
    if title.variant:
        _cell_text(drawing, (x0 + 135, y0 + 20, x0 + 160, y0 + 35), str(title.variant))
    _cell_text(drawing, (x0 + 160, y0 + 20, x1, y0 + 35), drawing.paper)
    _cell_text(drawing, (x0 + 135, y0 + 15, x1, y0 + 20), f"Sheet {number} of {total}", heights=(2.5,))
    group = f"Group {title.group}" if title.group else "Group"
    _cell_text(drawing, (x0 + 135, y0, x1, y0 + 15), group, heights=(3.5, 2.5))


class _Ruler:
    """Rules of the title block, in mm from its lower left corner."""

    def __init__(self, drawing: Drawing, x0: float, y0: float):
        self.drawing, self.x0, self.y0 = drawing, x0, y0

    def h(self, xa: float, xb: float, y: float, width: float) -> None:
        self.drawing.add(Line(((self.x0 + xa, self.y0 + y), (self.x0 + xb, self.y0 + y)), layer="frame",
                              width=width))

    def v(self, x: float, ya: float, yb: float, width: float) -> None:
        self.drawing.add(Line(((self.x0 + x, self.y0 + ya), (self.x0 + x, self.y0 + yb)), layer="frame",
                              width=width))


def _cell_text(drawing: Drawing, cell, text: str, heights=TEXT_HEIGHTS, align: str = "center",
               layer: str = "frame") -> Text | None:
    """Put ``text`` in ``cell = (x0, y0, x1, y1)`` mm at the largest of ``heights`` it fits at,
    on as few lines (up to three, broken at spaces) as it needs; a text that cannot fit even so
    is shortened with an ellipsis. Returns the :class:`Text` (None for "")."""
    if not text:
        return None
    x0, y0, x1, y1 = cell
    room_w, room_h = x1 - x0 - 2 * CELL_PAD, y1 - y0 - 2 * CELL_PAD
    chosen = None
    for h in heights:
        for lines_allowed in (1, 2, 3):
            lines = _wrap(text, room_w / (0.7 * h * WIDTH_MARGIN), lines_allowed)
            if lines and h * (1.6 * len(lines) - 0.6) <= room_h + _TOL:
                chosen = (h, lines)
                break
        if chosen:
            break
    if chosen is None:
        h = min(heights)
        chars = max(int(room_w / (0.7 * h * WIDTH_MARGIN)), 2)
        chosen = (h, [text if len(text) <= chars else text[:chars - 1] + "…"])
    h, lines = chosen
    x = {"left": x0 + CELL_PAD, "center": (x0 + x1) / 2, "right": x1 - CELL_PAD}[align]
    return drawing.add(Text((x, (y0 + y1) / 2), "\n".join(lines), height=h, layer=layer, anchor=(align, "middle")))


def _wrap(text: str, max_chars: float, max_lines: int) -> list[str] | None:
    """``text`` broken at spaces into at most ``max_lines`` lines of at most ``max_chars``
    characters (None when it cannot be)."""
    lines = textwrap.wrap(text, max(1, int(max_chars)), break_long_words=False, break_on_hyphens=False)
    if not lines or len(lines) > max_lines or any(len(line) > max_chars + _TOL for line in lines):
        return None
    return lines


def _rectangle(box) -> tuple[tuple[float, float], ...]:
    x0, y0, x1, y1 = box
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))


_NUMBER = re.compile(r"^[-+−]?[\d.,]+(e[-+]?\d+)?\s*%?$")


def table(drawing: Drawing, box_top_left: tuple[float, float], header: list[str], rows: list[list[str]],
          widths: list[float], height: float = 3.5, name: str = "table") -> tuple[float, float, float, float]:
    """Rule a table with its upper left corner at ``box_top_left`` (mm).

    Parameters
    ----------
    header : list of str
        One heading per column (none empty; ``"\\n"`` breaks a heading into lines).
    rows : list of list of str
        The cells, each row as long as ``header``; numbers are set right, words left.
    widths : list of float
        Each column's width, mm.
    height : float
        Text height, mm; a row is ``2 height + 1`` mm tall.
    name : str
        The region the table's box is recorded as.

    Returns
    -------
    tuple of 4 float
        The table's box ``(x0, y0, x1, y1)``, mm.

    Raises ValueError for a column without a heading, a row of another length, or a cell wider
    than its column.
    """
    if len(header) != len(widths) or any(not str(h).strip() for h in header):
        raise ValueError(f"table {name!r}: every column needs a heading and a width "
                         f"({len(header)} headings for {len(widths)} widths)")
    for row in rows:
        if len(row) != len(header):
            raise ValueError(f"table {name!r}: the row {row!r} has {len(row)} cells for {len(header)} columns")
    x0, top = float(box_top_left[0]), float(box_top_left[1])
    edges = (x0 + np.concatenate([[0.0], np.cumsum(np.asarray(widths, float))])).tolist()
    row_h = 2 * height + 1
    header_lines = max(str(h).count("\n") + 1 for h in header)
    header_h = row_h + 1.6 * height * (header_lines - 1)
    bottoms = (top - header_h - row_h * np.arange(len(rows) + 1)).tolist()
    y_bottom = float(bottoms[-1])
    box = (x0, y_bottom, float(edges[-1]), top)
    for label, a, b in zip(header, edges[:-1], edges[1:]):
        _fitted(drawing, (a, top - header_h, b, top), str(label), height, "center", name)
    for r, row in enumerate(rows):
        for label, a, b in zip(row, edges[:-1], edges[1:]):
            align = "right" if _NUMBER.match(str(label).strip()) else "left"
            _fitted(drawing, (a, bottoms[r + 1], b, bottoms[r]), str(label), height, align, name)
    drawing.add(Line(_rectangle(box), layer="text", width=0.5, closed=True))
    for y, width in zip(bottoms[:-1], [0.5] + [THIN_RULE] * len(rows)):
        drawing.add(Line(((x0, float(y)), (float(edges[-1]), float(y))), layer="text", width=width))
    for x in edges[1:-1]:
        drawing.add(Line(((float(x), y_bottom), (float(x), top)), layer="text", width=THIN_RULE))
    drawing.region(name, box)
    return box


def _fitted(drawing: Drawing, cell, text: str, height: float, align: str, name: str) -> None:
    """A table cell's text at ``height``; ValueError naming the cell when it is wider than the cell."""
    if not text:
        return
    x0, y0, x1, y1 = cell
    x = {"left": x0 + CELL_PAD, "center": (x0 + x1) / 2, "right": x1 - CELL_PAD}[align]
    item = Text((x, (y0 + y1) / 2), text, height=height, anchor=(align, "middle"))
    bx0, _, bx1, _ = item.box()
    needed = (bx1 - bx0) * WIDTH_MARGIN + 2 * CELL_PAD
    if needed > x1 - x0 + _TOL:
        raise ValueError(f"table {name!r}: the cell {text!r} needs {needed:.1f} mm at {height:g} mm, "
                         f"its column is {x1 - x0:.1f} mm wide")
    drawing.add(item)


def scales_table(drawing: Drawing, top_left: tuple[float, float],
                 height: float = 3.5) -> tuple[float, float, float, float]:
    """A one-column table headed "Scales" listing ``drawing.scales`` (``μ_l = 0.002 m/mm``)
    with its upper left corner at ``top_left`` (mm); records the region ``"scales"`` and
    returns its box ``(x0, y0, x1, y1)``, mm."""
    rows = [[str(s)] for s in drawing.scales.values()]
    longest = max([len("Scales")] + [len(r[0]) for r in rows])
    width = max(40.0, float(np.ceil(0.7 * WIDTH_MARGIN * height * longest + 2 * CELL_PAD + 1)))
    return table(drawing, top_left, ["Scales"], [[r[0]] for r in rows], [width], height=height, name="scales")


def extent(drawing: Drawing, item) -> tuple[float, float, float, float]:
    """Extent ``(x0, y0, x1, y1)`` mm of a primitive, a turned text's box turned about its
    anchor point (:meth:`Drawing.bounds` for the rest)."""
    if isinstance(item, Text) and item.angle % 360.0:
        x0, y0, x1, y1 = item.box()
        corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]) - item.at
        a = np.radians(item.angle)
        turned = corners @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]) + item.at
        return (float(turned[:, 0].min()), float(turned[:, 1].min()),
                float(turned[:, 0].max()), float(turned[:, 1].max()))
    return drawing.bounds(item)


def layout_problems(drawing: Drawing) -> list[str]:
    """What a teacher would reject in the layout of ``drawing``, one sentence each ([] when
    none): an item outside the frame's inner box, an item over the title block (the frame
    layer's own items excepted), two regions overlapping (the "frame" region holds them all),
    a region outside the frame, two texts overlapping each other."""
    regions = {r.name: r.box for r in drawing.regions}
    problems: list[str] = []
    frame = regions.get("frame", (0.0, 0.0) + drawing.size)
    block = regions.get("title block")
    for item in drawing.items:
        if item.layer == "frame":
            continue
        box = extent(drawing, item)
        if not _inside(box, frame):
            problems.append(f"{_describe(item)} reaches outside the frame ({_span(box)}; the frame is {_span(frame)})")
        if block is not None and _overlap(box, block):
            problems.append(f"{_describe(item)} lies over the title block ({_span(box)})")
    named = [(n, b) for n, b in regions.items() if n != "frame"]
    for name, box in named:
        if not _inside(box, frame):
            problems.append(f"the region {name!r} ({_span(box)}) reaches outside the frame")
    for (na, ba), (nb, bb) in itertools.combinations(named, 2):
        if _overlap(ba, bb):
            problems.append(f"the regions {na!r} ({_span(ba)}) and {nb!r} ({_span(bb)}) overlap")
    texts = [item for item in drawing.items if isinstance(item, Text)]
    if len(texts) > 1:
        boxes = np.array([extent(drawing, t) for t in texts])
        apart = ((boxes[:, None, 0] >= boxes[None, :, 2] - _TOL) | (boxes[None, :, 0] >= boxes[:, None, 2] - _TOL)
                 | (boxes[:, None, 1] >= boxes[None, :, 3] - _TOL) | (boxes[None, :, 1] >= boxes[:, None, 3] - _TOL))
        for i, j in zip(*np.nonzero(np.triu(~apart, 1))):
            problems.append(f"{_describe(texts[i])} and {_describe(texts[j])} overlap")
    return problems


def _inside(box, outer) -> bool:
    return (box[0] >= outer[0] - _TOL and box[1] >= outer[1] - _TOL and box[2] <= outer[2] + _TOL
            and box[3] <= outer[3] + _TOL)


def _overlap(a, b) -> bool:
    """Whether two boxes share an area (touching edges do not)."""
    return a[0] < b[2] - _TOL and b[0] < a[2] - _TOL and a[1] < b[3] - _TOL and b[1] < a[3] - _TOL


def _span(box) -> str:
    return f"x {box[0]:.1f}–{box[2]:.1f}, y {box[1]:.1f}–{box[3]:.1f} mm"


def _describe(item) -> str:
    if isinstance(item, Text):
        shown = item.text.replace("\n", " ")
        return f"the text {shown[:40]!r} at ({item.at[0]:.1f}, {item.at[1]:.1f}) mm"
    return f"a {type(item).__name__.lower()} on the {item.layer!r} layer"
