"""The page toolkit of the course's PDFs: A4 pages, text measured and wrapped, blocks laid out.

What the assignment sheet (:mod:`~linkage.course.sheets`) and the overview of variants
(:mod:`~linkage.course.overview`) share: the page's size, margins and fonts, an empty A4 figure
(:func:`new_page`) in the style every page is laid out with (:func:`page_style`), widths of texts
on paper and their wrapping (:class:`Measure`), text, rules and shading placed in inches from the
page's corner (:func:`write`, :func:`rule`, :func:`shade`), blocks flowed down a page
(:class:`Block`, :func:`flow`) and over as many pages as they need (:func:`paginate`; a table,
:func:`table_block`, splits between rows), the footer, and figures written as the pages of one
PDF (:func:`pdf_bytes`).

**Reproducible.** The same input gives byte-identical PDFs, whatever the current directory, the
time or ``SOURCE_DATE_EPOCH``: the PDF carries no creation or modification date, a fixed
producer and creator, fonts embedded as TrueType subsets (``pdf.fonttype`` 42, which also keeps
the text searchable and extractable), and every page is laid out from matplotlib's built-in
defaults (not the user's ``matplotlibrc``) at a fixed dpi. The bytes may differ between
matplotlib or font versions.

**Processes.** Figures are made with :class:`matplotlib.figure.Figure` and an Agg canvas of
their own (to measure text), never through pyplot's global figure manager, and saved with the
PDF backend; the functions can run in worker processes (not in threads of one process: the
style is set through matplotlib's process-wide ``rcParams`` for the duration of a call). Without
matplotlib they raise :class:`~linkage.report.style.PlotExtraMissing`.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Callable

from ..errors import InputError
from ..report.style import INSTALL_HINT, PlotExtraMissing

__all__ = ["A4", "MM", "SIDE", "TOP", "BOTTOM", "DPI", "TITLE", "HEADING", "TEXT", "TABLE", "FOOT", "LEADING",
           "Block", "Measure", "flow", "footer", "line_height", "new_page", "page_style", "paginate", "pdf_bytes",
           "rule", "shade", "table_block", "write"]

#: A4 portrait, inches (210 x 297 mm)
A4 = (210 / 25.4, 297 / 25.4)
MM = 1 / 25.4          # inches per millimetre
#: page margins, inches: left and right, top, bottom (the footer sits in the bottom margin)
SIDE, TOP, BOTTOM = 15 * MM, 14 * MM, 16 * MM
FOOTER_Y = 8 * MM       # baseline of the footer above the paper's bottom edge
#: dpi of the figures (fixes the label placement of the drawing, which works in pixels)
DPI = 100
#: font sizes, points
TITLE, HEADING, TEXT, TABLE, FOOT = 15, 11, 9.5, 9, 8
#: line spacing, as a multiple of the font size
LEADING = 1.28
#: the fixed metadata of every PDF (no dates: see the module's docstring)
PDF_METADATA = {"Creator": "linkage", "Producer": "linkage (matplotlib PDF backend)",
                "CreationDate": None, "ModDate": None}
#: the rcParams a page is laid out with, on top of matplotlib's built-in defaults
SHEET_STYLE = {"pdf.fonttype": 42, "font.family": "DejaVu Sans", "axes.unicode_minus": True,
         "pdf.compression": 6, "figure.dpi": DPI, "savefig.dpi": DPI}



# ----------------------------------------------------------------------------------------------
# matplotlib without pyplot, text measured and wrapped
# ----------------------------------------------------------------------------------------------


def _matplotlib():
    """The ``matplotlib`` module, or :class:`PlotExtraMissing` with the install hint."""
    try:
        import matplotlib
        import matplotlib.backends.backend_agg  # noqa: F401
        import matplotlib.backends.backend_pdf  # noqa: F401
        import matplotlib.figure  # noqa: F401
    except ImportError as exc:
        raise PlotExtraMissing(INSTALL_HINT) from exc
    return matplotlib


def page_style():
    """A context with matplotlib's built-in defaults plus :data:`SHEET_STYLE` (undone on exit)."""
    import contextlib

    matplotlib = _matplotlib()

    @contextlib.contextmanager
    def context():
        with matplotlib.rc_context():
            matplotlib.rcdefaults()
            matplotlib.rcParams.update(SHEET_STYLE)
            yield

    return context()


def new_page(landscape: bool = False):
    """An empty A4 figure with its own Agg canvas (text measuring; no pyplot)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    size = A4[::-1] if landscape else A4
    fig = Figure(figsize=size, dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


class Measure:
    """Widths of texts on paper, inches, from the Agg renderer of a high-dpi canvas."""

    def __init__(self):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        self.renderer = FigureCanvasAgg(Figure(dpi=600)).get_renderer()
        self._cache: dict[tuple[str, float, bool], float] = {}

    def width(self, text: str, size: float, bold: bool = False, math: bool = False) -> float:
        """Width of ``text`` on paper, inches; ``math``: the text is mathtext (``"$J_{S2}$"``)."""
        from matplotlib.font_manager import FontProperties

        key = (text, size, bold, math)
        if key not in self._cache:
            prop = FontProperties(size=size, weight="bold" if bold else "normal")
            w, _, _ = self.renderer.get_text_width_height_descent(text, prop, ismath=bool(math and "$" in text))
            self._cache[key] = w / self.renderer.dpi
        return self._cache[key]

    def shortened(self, text: str, width: float, size: float) -> str:
        """``text`` on one line no wider than ``width`` inches: cut with "…" when it is wider."""
        text = " ".join(text.split())
        if self.width(text, size) <= width:
            return text
        keep = max((k for k in range(len(text)) if self.width(text[:k].rstrip() + "…", size) <= width), default=0)
        return text[:keep].rstrip() + "…"

    def wrap(self, text: str, width: float, size: float, bold: bool = False) -> list[str]:
        """``text`` in lines no wider than ``width`` inches, broken between words (inside a word
        only when the word alone is wider); explicit newlines are kept."""
        lines: list[str] = []
        for paragraph in str(text).split("\n"):
            line = ""
            for word in paragraph.split():
                candidate = f"{line} {word}" if line else word
                if self.width(candidate, size, bold) <= width:
                    line = candidate
                    continue
                if line:
                    lines.append(line)
                line = word
                while self.width(line, size, bold) > width and len(line) > 1:
                    cut = max(1, max(k for k in range(1, len(line) + 1)
                                     if k == 1 or self.width(line[:k], size, bold) <= width))
                    lines.append(line[:cut])
                    line = line[cut:]
            lines.append(line)
        return lines


def line_height(size: float) -> float:
    """Height of a line of text of ``size`` points, inches."""
    return LEADING * size / 72


#: height of the first baseline below the top of a line of text, as a multiple of the font size
ASCENT = 0.82


def write(fig, x: float, y: float, text: str, size: float, *, bold: bool = False, ha: str = "left",
           colour: str = "black", va: str = "top", gid: str | None = None, math: bool = False) -> None:
    """Text at (x, y) inches from the page's bottom-left corner, as written (mathtext only where
    ``math``: ``"$J_{S2}$"``).

    With ``va="top"`` (the default) ``y`` is the top of the first line and every line of the text
    is placed on its own baseline, :data:`LEADING` apart, so that texts side by side (a number and
    its item, the cells of a row) share their baselines whatever glyphs they hold.
    """
    w, h = fig.get_size_inches()
    style = dict(fontsize=size, fontweight="bold" if bold else "normal", ha=ha, color=colour, parse_math=math,
                 gid=gid)
    if va != "top":
        fig.text(x / w, y / h, text, va=va, **style)
        return
    for k, line in enumerate(text.split("\n")):
        fig.text(x / w, (y - (ASCENT + LEADING * k) * size / 72) / h, line, va="baseline", **style)


def rule(fig, x0: float, x1: float, y: float, lw: float = 0.6, colour: str = "0.3") -> None:
    from matplotlib.lines import Line2D

    w, h = fig.get_size_inches()
    fig.add_artist(Line2D([x0 / w, x1 / w], [y / h, y / h], lw=lw, color=colour, transform=fig.transFigure))


def shade(fig, x0: float, y0: float, width: float, height: float, colour: str = "0.93") -> None:
    from matplotlib.patches import Rectangle

    w, h = fig.get_size_inches()
    fig.add_artist(Rectangle((x0 / w, y0 / h), width / w, height / h, fc=colour, ec="none",
                             transform=fig.transFigure, zorder=-1))


def pdf_bytes(figures: Sequence[Any], title: str) -> bytes:
    """The figures as the pages of one PDF, reproducibly (no dates, fixed producer)."""
    from matplotlib.backends.backend_pdf import PdfPages

    buffer = io.BytesIO()
    with PdfPages(buffer, metadata={"Title": title, **PDF_METADATA}) as pdf:
        for fig in figures:
            pdf.savefig(fig)
    return buffer.getvalue()


# ----------------------------------------------------------------------------------------------
# blocks of text on a page
# ----------------------------------------------------------------------------------------------


@dataclass(eq=False)
class Block:
    """Something laid out down a page: its height, inches, and how to draw it from a top edge.

    ``split(room)``, where given, cuts a block taller than a page into ``(first, rest)``: a first
    part no taller than ``room`` inches (None when not even its first lines fit) and the rest
    (None when nothing is left); :func:`paginate` uses it for a block taller than a page, and for
    any that does not fit the rest of a page when ``breakable``.
    """

    height: float
    draw: Callable[[Any, float], None]
    gap: float = 0.16            # space below it, inches
    split: Callable[[float], tuple[Block | None, Block | None]] | None = None
    breakable: bool = False      # split at the foot of a page rather than start the next page whole


def flow(fig, blocks: Sequence[Block], top: float) -> float:
    """Draw the blocks down the page from ``top`` (inches); the top of what would come next."""
    for block in blocks:
        block.draw(fig, top)
        top -= block.height + block.gap
    return top


def paginate(first: Sequence[Block], blocks: Sequence[Block], continued: Callable[[], list[Block]],
             room: float = A4[1] - TOP - BOTTOM) -> list[list[Block]]:
    """The blocks of each page: page 1 starts with ``first``, every later page with
    ``continued()`` (a title saying so); ``blocks`` follow in order, each on the page it fits.

    A block that does not fit the rest of a page starts the next one, whole, when it fits a page
    and is not ``breakable``; a breakable one, and one taller than a page, is split
    (:attr:`Block.split`) over as many pages as it needs.
    Nothing is cut off: a block that can be neither placed nor split is an InputError.
    """
    def used(page: list[Block]) -> float:
        return sum(b.height + b.gap for b in page)

    pages = [list(first)]
    empty = not first                           # the page holds nothing but its "continued" title
    queue = list(blocks)
    page_room = room - used(continued())
    while queue:
        block = queue.pop(0)
        left = room - used(pages[-1])
        if block.height <= left + 1e-9:
            pages[-1].append(block)
            empty = False
            continue
        if (block.breakable or block.height > page_room + 1e-9) and block.split is not None:
            part, rest = block.split(left)
        else:
            part, rest = None, block
        if part is None and empty:
            raise InputError(f"a block of {block.height:.2f} in does not fit an A4 page of {page_room:.2f} in "
                             "and cannot be split: shorten the text")
        if part is not None:
            pages[-1].append(part)
        if rest is not None:
            pages.append(continued())
            empty = True
            queue.insert(0, rest)
    return pages


def table_block(measure: Measure, width: float, columns: Sequence[tuple[str, str, float | None, bool]],
                rows: Sequence[Sequence[str]], heading: str = "", size: float = TABLE, x0: float = SIDE,
                gap: float = 0.16, breakable: bool = False) -> Block:
    """A table with a bold heading above it, a header row and rows shaded every other one.

    ``columns``: ``(title, gid, width, math)`` each; a width of None shares what the others
    leave; ``math`` cells are mathtext and not wrapped, the others are wrapped to their column.
    A row of one cell is the title of a section of the table: bold, across the columns. A table
    taller than a page (or any, when ``breakable``) splits between rows over pages: the heading
    (marked "(continued)"), the header row and the title of the section it breaks in are repeated.
    """
    fixed = sum(w for _, _, w, _ in columns if w is not None)
    free = [k for k, c in enumerate(columns) if c[2] is None]
    widths = [c[2] if c[2] is not None else max(width - fixed, 0.5) / max(len(free), 1) for c in columns]
    cells = [[measure.wrap(row[0], sum(widths) - 0.12, size, bold=True)] if len(row) == 1 else
             [[text] if math else measure.wrap(text, w - 0.12, size)
              for text, w, (_, _, _, math) in zip(row, widths, columns, strict=True)] for row in rows]
    return _table_part(_Table(widths, columns, heading, size, x0, gap, breakable), cells, False)


@dataclass(frozen=True)
class _Table:
    """What the parts of a table share."""

    widths: list[float]
    columns: Sequence[tuple[str, str, float | None, bool]]
    heading: str
    size: float
    x0: float
    gap: float
    breakable: bool

    def height(self, row: list[list[str]]) -> float:
        return max(len(c) for c in row) * line_height(self.size) + (0.1 if len(row) == 1 else 0.035)


def _table_part(table: _Table, cells: list[list[list[str]]], continued: bool) -> Block:
    size, x0 = table.size, table.x0
    top_part = (line_height(HEADING) + 0.04 if table.heading else 0.0) + line_height(size) + 0.07
    x = [x0 + sum(table.widths[:k]) for k in range(len(table.widths))]
    total = sum(table.widths)
    heights = [table.height(row) for row in cells]

    def draw(fig, top):
        if table.heading:
            write(fig, x0, top, table.heading + (" (continued)" if continued else ""), HEADING, bold=True,
                  gid="heading")
            top -= line_height(HEADING) + 0.04
        for k, (title, *_rest) in enumerate(table.columns):
            write(fig, x[k] + 0.06, top - 0.03, title, size, bold=True)
        y = top - line_height(size) - 0.07
        rule(fig, x0, x0 + total, y, lw=0.8, colour="0.2")
        shaded = 0
        for row, h in zip(cells, heights, strict=True):
            if len(row) == 1:
                write(fig, x0 + 0.06, y - 0.08, "\n".join(row[0]), size, bold=True, gid="section")
                rule(fig, x0, x0 + total, y - h, lw=0.5, colour="0.5")
                shaded, y = 0, y - h
                continue
            if shaded % 2:
                shade(fig, x0, y - h, total, h)
            shaded += 1
            for j, (cell, (_, gid, _, math)) in enumerate(zip(row, table.columns, strict=True)):
                write(fig, x[j] + 0.06, y - 0.025, "\n".join(cell), size, gid=gid, math=math)
            y -= h
        rule(fig, x0, x0 + total, y, lw=0.8, colour="0.2")

    def split(room: float):
        fits, height = 0, top_part + 0.02
        while fits < len(cells) and height + heights[fits] <= room:
            height += heights[fits]
            fits += 1
        while fits and len(cells[fits - 1]) == 1:             # no section title at the foot of a page
            fits -= 1
        if fits == len(cells):
            return block, None
        if fits < min(2, len(cells)):
            return None, block
        rest = cells[fits:]
        section = next((row for row in reversed(cells[:fits]) if len(row) == 1), None)
        if section is not None and len(rest[0]) != 1:
            rest = [[[section[0][0] + " (continued)", *section[0][1:]]], *rest]
        return _table_part(table, cells[:fits], continued), _table_part(table, rest, True)

    block = Block(top_part + sum(heights) + 0.02, draw, table.gap, split, table.breakable)
    return block


def footer(fig, measure: Measure, left: str, right: str = "") -> None:
    """The footer line: ``left`` (shortened with "…" when it would run into ``right``) and ``right``."""
    width = fig.get_size_inches()[0]
    room = width - 2 * SIDE - (measure.width(right, FOOT) + 0.3 if right else 0.0)
    write(fig, SIDE, FOOTER_Y, measure.shortened(left, room, FOOT), FOOT, colour="0.3", va="baseline",
           gid="footer")
    if right:
        write(fig, width - SIDE, FOOTER_Y, right, FOOT, colour="0.3", va="baseline", ha="right", gid="page-number")
