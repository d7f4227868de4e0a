"""The overview of a course's variants: their table as an A4 PDF (matplotlib only).

:func:`overview_pdf` -- the table of all variants of a course: A4 (landscape when the table is
wide), at most :data:`ROWS_PER_PAGE` rows a page, the header (each column's name, its unit under
it) on every page, "page k of K", then the notes. :func:`overview_figures` gives the same pages as matplotlib figures. Typeset with
:mod:`~linkage.course.typesetting`, like the assignment sheets (:mod:`~linkage.course.sheets`).

**Reproducible.** The same input gives byte-identical PDFs (no dates, fixed metadata, embedded
fonts, matplotlib's built-in defaults; see :mod:`~linkage.course.typesetting`), and the
functions can run in worker processes. Without matplotlib they raise
:class:`~linkage.report.style.PlotExtraMissing`.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .typesetting import (
    A4,
    BOTTOM,
    HEADING,
    SIDE,
    TEXT,
    TOP,
    Measure,
    footer,
    line_height,
    new_page,
    page_style,
    pdf_bytes,
    rule,
    shade,
    write,
)

__all__ = ["ROWS_PER_PAGE", "overview_figures", "overview_pdf"]

#: rows of the overview's table on one page at most
ROWS_PER_PAGE = 35


# ----------------------------------------------------------------------------------------------
# the overview of all variants
# ----------------------------------------------------------------------------------------------


def _is_number(text: str) -> bool:
    try:
        float(text.replace("−", "-"))
    except ValueError:
        return False
    return True


@dataclass
class _Table:
    """The overview's table measured: font, column widths (inches), wrapped header and cells."""

    font: float
    widths: list[float]
    header: list[list[str]]
    units: list[str]
    cells: list[list[list[str]]]
    right: list[bool]

    @property
    def width(self) -> float:
        return sum(self.widths)


PAD = 0.07   # inches of padding at each side of a cell


def _measure_table(measure: Measure, header: list[str], rows: list[list[str]], room: float,
                   units: list[str]) -> _Table:
    """Column widths (inches) at the largest font from 9 pt down to 6 pt with which the table fits
    ``room``: each column as wide as its widest cell, its unit and the widest piece of its name
    (names break between words and after underscores), then whole names on one line while the
    room lasts; still too wide at 6 pt, the columns share the room by their needs and cells wrap."""
    right = [all(_is_number(r[c]) for r in rows if r[c].strip()) and any(r[c].strip() for r in rows)
             for c in range(len(header))]
    font = 9.0
    while True:
        cell = [max([measure.width(r[c], font) for r in rows] + [0.0]) for c in range(len(header))]
        word = [max([measure.width(w, font, True) for w in _name_pieces(h)] + [measure.width(u, font)])
                for h, u in zip(header, units, strict=True)]
        full = [measure.width(h, font, True) for h in header]
        need = [max(c, w) + 2 * PAD for c, w in zip(cell, word, strict=True)]
        if sum(need) <= room or font <= 6.0:
            break
        font -= 0.5
    if sum(need) > room:
        widths = [room * n / sum(need) for n in need]
    else:                    # whole headers on one line, the cheapest first, while the room lasts
        widths = list(need)
        for extra, c in sorted((f + 2 * PAD - n, c) for c, (n, f) in enumerate(zip(need, full, strict=True))):
            if 0 < extra <= room - sum(widths):
                widths[c] += extra
    spare = room - sum(widths)
    if sum(widths) < room and spare < 0.5 * room:   # fill the page's width when it is nearly full
        widths = [w + spare * w / sum(widths) for w in widths]
    wrapped_header = [_wrap_name(measure, h, w - 2 * PAD, font) for h, w in zip(header, widths, strict=True)]
    cells = [[measure.wrap(r[c], widths[c] - 2 * PAD, font) for c in range(len(header))] for r in rows]
    return _Table(font, widths, wrapped_header, list(units), cells, right)


def _name_pieces(name: str) -> list[str]:
    """A column name cut where it may break: after spaces and after underscores
    (``"min_transmission_angle_deg"`` -> ``min_``, ``transmission_``, ``angle_``, ``deg``)."""
    return [piece for word in name.split() for piece in re.findall(r"[^_]+_*|_+", word)]


def _wrap_name(measure: Measure, name: str, width: float, size: float) -> list[str]:
    """A column name (bold) in lines no wider than ``width`` inches, broken between words and
    after underscores (inside a piece only when it alone is wider)."""
    lines: list[str] = []
    for word in name.split():
        pieces = _name_pieces(word)
        line = lines.pop() if lines and measure.width(f"{lines[-1]} {pieces[0]}", size, True) <= width else None
        line = f"{line} " if line is not None else ""
        for piece in pieces:
            if line and measure.width(line + piece, size, True) > width:
                lines.append(line.rstrip())
                line = ""
            line += piece
        lines.append(line.rstrip())
    return [part for line in lines for part in measure.wrap(line, width, size, True)] or [""]


def _checked_overview_input(title, header, rows, notes, units) -> tuple[list[str], list[list[str]], list[str],
                                                                        list[str]]:
    if not isinstance(title, str) or not title.strip():
        raise InputError(f"the overview's title must be a non-empty string, got {title!r}")
    header = list(header)
    if not header or not all(isinstance(h, str) for h in header):
        raise InputError(f"the overview's header must be a non-empty sequence of strings, got {header!r}")
    units = [""] * len(header) if units is None else units
    if isinstance(units, str) or len(units) != len(header) or not all(isinstance(u, str) for u in units):
        raise InputError(f"the overview's units must be {len(header)} strings (one per column of the header "
                         f"{header}; '' for none), got {units!r}")
    checked = []
    for k, row in enumerate(rows, start=1):
        row = list(row) if not isinstance(row, str) else None
        if row is None or len(row) != len(header) or not all(isinstance(c, str) for c in row):
            raise InputError(f"overview row {k} must be {len(header)} strings (one per column of the header "
                             f"{header}), got {rows[k - 1]!r}")
        checked.append(row)
    if isinstance(notes, str) or not all(isinstance(n, str) for n in notes):
        raise InputError(f"the overview's notes must be a sequence of strings, got {notes!r}")
    return header, checked, list(notes), list(units)


def _pages_of_rows(heights: Sequence[float], room: float) -> list[list[int]]:
    """Row indices per page: at most :data:`ROWS_PER_PAGE` rows and ``room`` inches a page."""
    pages: list[list[int]] = [[]]
    used = 0.0
    for k, h in enumerate(heights):
        if pages[-1] and (len(pages[-1]) >= ROWS_PER_PAGE or used + h > room):
            pages.append([])
            used = 0.0
        pages[-1].append(k)
        used += h
    return pages


def overview_figures(*, title: str, header: Sequence[str], rows: Sequence[Sequence[str]],
                     notes: Sequence[str] = (), units: Sequence[str] | None = None) -> list:
    """The pages of :func:`overview_pdf` as A4 matplotlib figures, each with an Agg canvas of its
    own."""
    header, rows, notes, units = _checked_overview_input(title, header, rows, notes, units)
    with page_style():
        return _overview_pages(title, header, rows, notes, units)


def _overview_pages(title: str, header: list[str], rows: list[list[str]], notes: list[str],
                    units: list[str]) -> list:
    measure = Measure()
    portrait_room = A4[0] - 2 * SIDE
    table = _measure_table(measure, header, rows, portrait_room, units)
    landscape = table.width > portrait_room + 1e-9 or table.font < 9.0
    if landscape:
        table = _measure_table(measure, header, rows, A4[1] - 2 * SIDE, units)
    page_w, page_h = (A4[1], A4[0]) if landscape else A4
    line = line_height(table.font)
    head_h = (max(len(h) for h in table.header) + any(table.units)) * line + 0.08
    title_lines = measure.wrap(title, page_w - 2 * SIDE, HEADING + 2, bold=True)
    title_h = len(title_lines) * line_height(HEADING + 2) + 0.12
    room = page_h - TOP - BOTTOM - title_h - head_h
    row_h = max(min(room / ROWS_PER_PAGE, 1.55 * table.font / 72), line + 0.01)   # per line of a row
    heights = [max(len(c) for c in cells) * row_h for cells in table.cells]
    pages_rows = _pages_of_rows(heights, room) if rows else [[]]
    note_lines = _note_lines(measure, notes, page_w - 2 * SIDE)
    layout = _place_notes(pages_rows, heights, note_lines, room, page_h - TOP - BOTTOM - title_h)
    figures = []
    for k, (indices, notes_here) in enumerate(layout):
        fig = new_page(landscape)
        top = page_h - TOP
        write(fig, SIDE, top, "\n".join(title_lines), HEADING + 2, bold=True, gid="title")
        top -= title_h
        if indices is not None:
            top = _draw_table_page(fig, table, indices, heights, top, head_h)
        if notes_here:
            _draw_notes(fig, notes_here, top - 0.15)
        footer(fig, measure, title, f"page {k + 1} of {len(layout)}")
        figures.append(fig)
    return figures


def _note_lines(measure: Measure, notes: list[str], width: float) -> list[tuple[str, str]]:
    """The notes as lines ``(text, kind)``, kind ``"heading"``, ``"first"`` (a note's first line,
    with a bullet) or ``"more"``."""
    if not notes:
        return []
    lines = [("Notes", "heading")]
    for note in notes:
        wrapped = measure.wrap(note, width - 0.25, TEXT)
        lines += [(text, "first" if k == 0 else "more") for k, text in enumerate(wrapped)]
    return lines


def _place_notes(pages_rows, heights, note_lines, room, page_room):
    """``[(row indices or None, note lines), ...]``: the table's pages, the notes after the last
    row as far as they fit there, the rest on pages of their own."""
    layout = [(indices, []) for indices in pages_rows]
    if not note_lines:
        return layout
    used = sum(heights[k] for k in pages_rows[-1]) if pages_rows[-1] else 0.0
    per_line = line_height(TEXT)
    extra = line_height(HEADING) - per_line + 0.3     # the heading's larger line, the space above the notes
    fit = max(0, int((room - used - extra) // per_line))
    if fit >= min(3, len(note_lines)):
        layout[-1] = (layout[-1][0], note_lines[:fit])
        rest = note_lines[fit:]
    else:
        rest = note_lines
    per_page = max(1, int((page_room - extra) // per_line))
    for k in range(0, len(rest), per_page):
        layout.append((None, rest[k:k + per_page]))
    return layout


def _draw_table_page(fig, table: _Table, indices: list[int], heights: list[float], top: float,
                     head_h: float) -> float:
    """The header and the rows ``indices``; the top of what comes below, inches."""
    x = SIDE + np.concatenate([[0.0], np.cumsum(table.widths)])
    line = line_height(table.font)
    unit_top = top - 0.03 - max(len(h) for h in table.header) * line   # the units on one line under the names
    for c, lines in enumerate(table.header):
        anchor, ha = (x[c + 1] - PAD, "right") if table.right[c] else (x[c] + PAD, "left")
        write(fig, anchor, top - 0.03, "\n".join(lines), table.font, bold=True, ha=ha, gid="header",
               va="top")
        if table.units[c]:
            write(fig, anchor, unit_top, table.units[c], table.font, ha=ha, gid="header-unit", va="top")
    top -= head_h
    rule(fig, x[0], x[-1], top, lw=0.9, colour="0.15")
    for n, k in enumerate(indices):
        h = heights[k]
        if n % 2:
            shade(fig, x[0], top - h, x[-1] - x[0], h)
        for c, lines in enumerate(table.cells[k]):
            anchor, ha = (x[c + 1] - PAD, "right") if table.right[c] else (x[c] + PAD, "left")
            write(fig, anchor, top - (h - len(lines) * line) / 2 - 0.005 * table.font / 9, "\n".join(lines),
                   table.font, ha=ha, gid="cell")
        top -= h
    rule(fig, x[0], x[-1], top, lw=0.9, colour="0.15")
    return top


def _draw_notes(fig, lines: list[tuple[str, str]], top: float) -> None:
    for text, kind in lines:
        if kind == "heading":
            write(fig, SIDE, top, text, HEADING, bold=True, gid="notes-heading")
            top -= line_height(HEADING)
            continue
        if kind == "first":
            write(fig, SIDE + 0.08, top, "•", TEXT)
        write(fig, SIDE + 0.25, top, text, TEXT, gid="note")
        top -= line_height(TEXT)


def overview_pdf(*, title: str, header: Sequence[str], rows: Sequence[Sequence[str]],
                 notes: Sequence[str] = (), units: Sequence[str] | None = None) -> bytes:
    """The table of all variants as an A4 PDF, then the notes.

    Portrait when the table fits the width of a portrait page at 9 pt, else landscape (down to
    6 pt, then the columns share the width and cells wrap). At most :data:`ROWS_PER_PAGE` rows a
    page, the header on every page, columns of numbers right-aligned; a footer with the title and
    "page k of K". The notes (e.g. how many draws each feasibility rule rejected) follow the last
    row, on further pages when they do not fit.

    Parameters
    ----------
    title : str
        The overview's title; also the footer and the PDF's title.
    header : sequence of str
        The column names.
    units : sequence of str, optional
        Printed under each column's name, as given (``"[kg·m²]"``; ``""`` for nothing); default
        none.
    rows : sequence of sequences of str
        One row of texts per variant, as many as the header has columns.
    notes : sequence of str
        Paragraphs after the table.

    Returns
    -------
    bytes
        The PDF; the same bytes for the same input (see the module's docstring).

    Raises
    ------
    InputError
        A row (or the units) of another length than the header, or a value that is not text.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pages = overview_figures(title=title, header=header, rows=rows, notes=notes, units=units)
    with page_style():
        return pdf_bytes(pages, title)
