"""Assignment sheets and the overview of variants as A4 PDF (linkage.course.sheets).

Oracles: the PDF's own structure (page objects, the page count, the media box of A4 = 210 x 297
mm = 595.28 x 841.89 pt), poppler's pdfinfo / pdftotext where installed (as a cross-check, and
for the text as a reader's program extracts it), the lengths of the variant (the crank OA, the
distance between the pivots, from the template's values) measured on the sheet's drawing in
inches of paper, closed-form input angles of position 1, and the bytes of a second rendering
in another process, directory, time and matplotlibrc.
"""

from __future__ import annotations

import hashlib
import math
import re
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path as FilePath

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="sheets need the plot extra, which the test extra installs: pip install \".[test]\"")

from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Patch  # noqa: E402
from matplotlib.path import Path  # noqa: E402

from linkage import MechanismBuilder  # noqa: E402
from linkage.errors import InputError, LinkageError  # noqa: E402
from linkage.course import sheets  # noqa: E402
from linkage.report.plots import PlotExtraMissing  # noqa: E402
from linkage.course.overview import ROWS_PER_PAGE, overview_figures, overview_pdf  # noqa: E402
from linkage.course.sheets import assignment_sheet, sheet_figures, standard_scale  # noqa: E402
from linkage.course.template import load_template  # noqa: E402

ROOT = FilePath(__file__).resolve().parents[1]
A4_PT = (210 / 25.4 * 72, 297 / 25.4 * 72)        # 595.28 x 841.89 pt
#: standard scales paper / real, from the largest down (ISO 5455 and 1:2.5, 1:4, 1:25, 1:40 ...)
STANDARD = [100, 50, 20, 10, 5, 2] + [1 / (m * 10 ** k) for k in range(8) for m in (1, 2, 2.5, 4, 5)]

PRESS_FREE = {"crank": 0.1, "ratio": 0.28, "offset_ratio": 0.18, "com_fraction": 0.33, "q_rod": 1800,
              "mass_slider": 500, "peak_force": 110000, "rpm": 90, "delta": 0.04, "inertia_0": 40.0}
SHAPER_FREE = {"crank": 0.08, "pivots": 0.17, "guide_height": 0.36, "rocker": 0.6, "q_rocker": 15, "mass_ram": 30,
               "cutting_force": 2000, "rpm": 50, "delta": 0.05, "inertia_0": 1.0}


def _number(value) -> str:
    return f"{value:.10g}" if isinstance(value, float) else str(value)


class Variant:
    """A variant of a shipped template with its sheet's inputs."""

    def __init__(self, template: str, free: dict):
        self.template = load_template(template)
        self.values = self.template.values(free)
        self.mechanism = self.template.mechanism(free, name=f"{template}_7")
        self.title = f"Assignment 7 — {template}"
        self.data = [(p.label or p.name, _number(self.values[p.name]), p.unit) for p in self.template.parameters]
        self.tasks = list(self.template.tasks)
        self.subtitle = self.template.description

    def kwargs(self) -> dict:
        return dict(title=self.title, data=self.data, tasks=self.tasks, subtitle=self.subtitle)


@pytest.fixture(scope="module")
def press():
    return Variant("press_slider_crank", PRESS_FREE)


@pytest.fixture(scope="module")
def shaper():
    return Variant("shaper_two_dyad", SHAPER_FREE)


@pytest.fixture(scope="module")
def press_pdf(press):
    return assignment_sheet(press.mechanism, **press.kwargs())


@pytest.fixture(scope="module")
def shaper_pdf(shaper):
    return assignment_sheet(shaper.mechanism, **shaper.kwargs())


def tiny_four_bar(k: float = 1e-3):
    """A crank-rocker four-bar with a crank of ``k`` m (frame 3k, coupler 3k, rocker 2.5k): no
    [dynamics], no output."""
    b = MechanismBuilder("tiny_four_bar")
    b.link("0", points={"O": (0.0, 0.0), "C": (3 * k, 0.0)})
    b.link("1", line=("O", "A"), length=k)
    b.link("2", line=("A", "B"), length=3 * k, points={"E": {"from": "A", "distance": 1.5 * k, "angle_deg": 30}})
    b.link("3", line=("C", "B"), length=2.5 * k)
    for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, a, c)
    b.inputs("1").assembly("B", left_of=("A", "C"))
    return b.build()


# -- reading a PDF ------------------------------------------------------------------------------


def page_count(pdf: bytes) -> int:
    """The page objects of the PDF, checked against the page tree's /Count (and pdfinfo)."""
    pages = len(re.findall(rb"/Type\s*/Page(?![A-Za-z])", pdf))
    counts = [int(c) for c in re.findall(rb"/Count\s+(\d+)", pdf)]
    assert counts == [pages], (counts, pages)
    if shutil.which("pdfinfo"):
        info = _poppler("pdfinfo", pdf)
        assert int(re.search(r"Pages:\s+(\d+)", info).group(1)) == pages
    return pages


def media_boxes(pdf: bytes) -> list[tuple[float, float]]:
    return [(float(w), float(h)) for w, h in
            re.findall(rb"/MediaBox\s*\[\s*0\s+0\s+([\d.]+)\s+([\d.]+)\s*\]", pdf)]


def _poppler(tool: str, pdf: bytes, *args: str) -> str:
    return subprocess.run([tool, *args, "-", "-"] if tool == "pdftotext" else [tool, "-"], input=pdf,
                          capture_output=True, check=True).stdout.decode("utf-8")


def pdf_text(pdf: bytes, page: int | None = None) -> str:
    """The text pdftotext extracts (layout kept, then whitespace collapsed); skips without poppler."""
    if not shutil.which("pdftotext"):
        pytest.skip("pdftotext (poppler-utils) is not installed: the PDF's text is checked through the figures only")
    pages = ["-f", str(page), "-l", str(page)] if page else []
    return " ".join(_poppler("pdftotext", pdf, "-layout", *pages).split())


def figure_texts(fig, gid: str | None = None) -> list[str]:
    return [t.get_text() for t in fig.texts if gid is None or t.get_gid() == gid]


def squeeze(text: str) -> str:
    return " ".join(text.split())


# -- the sheet: pages and text ----------------------------------------------------------------------


def test_the_press_sheet_is_one_a4_page(press_pdf, press):
    assert press_pdf.startswith(b"%PDF-")
    assert page_count(press_pdf) == 1
    assert media_boxes(press_pdf) == [pytest.approx(A4_PT, abs=0.01)]
    if shutil.which("pdfinfo"):
        assert "(A4)" in _poppler("pdfinfo", press_pdf)


def test_the_shaper_sheet_is_two_a4_pages(shaper_pdf, shaper):
    """Two pages, because of what the sheet holds: the shaper's drawing is tall (the 0.6 m
    rocker swings about pivots 0.17 m apart, the ram 0.36 m up), and the drawing always gets the
    largest standard scale the room under the title allows, 1:4, with most of the page's height;
    its 15 data rows and 7 tasks do not fit under it, so the data table and the tasks, each
    whole, go to page 2 (the data never shrink the drawing). With only 3 data rows and 1 task the
    text fits under it: one page at 1:4.
    (The press's flat slider-crank is drawn at 1:4 by the page's width with all its text under
    it: one page, test_the_press_sheet_is_one_a4_page.)"""
    assert len(shaper.data) == 15 and len(shaper.tasks) == 7
    pages = page_count(shaper_pdf)
    assert pages == 2
    assert media_boxes(shaper_pdf) == [pytest.approx(A4_PT, abs=0.01)] * 2
    figures = sheet_figures(shaper.mechanism, **shaper.kwargs())
    assert len(figures) == 2
    first, second = figures
    assert [ax.get_label() for ax in first.axes] == ["drawing"] and second.axes == []
    assert figure_texts(first, "data-value") == [] and figure_texts(first, "task") == []
    assert figure_texts(second, "title") == [f"{shaper.title} (continued)"]
    assert figure_texts(second, "data-value") == [v for _, v, _ in shaper.data]
    assert squeeze(" ".join(figure_texts(second, "task"))) == squeeze(" ".join(shaper.tasks))
    # the drawing on page 1 is as large as the drawing alone: the text went to page 2 for it
    assert figure_texts(first, "scale") == ["The mechanism to scale 1:4"]
    alone = sheet_figures(shaper.mechanism, **{**shaper.kwargs(), "data": [], "tasks": []})
    assert [figure_texts(f, "scale") for f in alone] == [["The mechanism to scale 1:4"]]
    short = sheet_figures(shaper.mechanism, **{**shaper.kwargs(), "data": shaper.data[:3], "tasks": shaper.tasks[:1]})
    assert [figure_texts(f, "scale") for f in short] == [["The mechanism to scale 1:4"]]
    assert figure_texts(short[0], "data-value") == [v for _, v, _ in shaper.data[:3]]


@pytest.mark.parametrize("which", ["press", "shaper"])
def test_the_figures_hold_the_title_every_row_and_every_task(which, request):
    variant = request.getfixturevalue(which)
    figures = sheet_figures(variant.mechanism, **variant.kwargs())
    texts = lambda gid: [t for fig in figures for t in figure_texts(fig, gid)]  # noqa: E731
    assert texts("title")[0] == variant.title
    assert texts("footer") == [variant.title] * len(figures)
    assert texts("data-value") == [v for _, v, _ in variant.data]
    assert texts("data-unit") == [u for _, _, u in variant.data]
    assert squeeze(" ".join(texts("data-label"))) == squeeze(" ".join(label for label, _, _ in variant.data))
    assert squeeze(" ".join(texts("task"))) == squeeze(" ".join(variant.tasks))
    assert squeeze(" ".join(texts("subtitle"))) == squeeze(variant.subtitle)


@pytest.mark.parametrize("which", ["press", "shaper"])
def test_the_pdf_text_holds_the_title_every_row_and_every_task(which, request):
    variant = request.getfixturevalue(which)
    text = pdf_text(request.getfixturevalue(f"{which}_pdf"))
    assert text.startswith(variant.title)
    assert text.rstrip().endswith(variant.title)              # the footer: the title only, no date
    for label, value, unit in variant.data:                   # a row reads label, value, unit
        # a label wrapped in its column reads its first line, the value and unit, then the rest
        words = label.split()
        assert any(re.search(rf"{re.escape(' '.join(words[:k]))} {re.escape(value)}"
                             rf"{' ' + re.escape(unit) if unit else ''} {re.escape(' '.join(words[k:]))}".rstrip()
                             + r"(?= |$)", text) for k in range(1, len(words) + 1)), (label, value, unit)
    for k, task in enumerate(variant.tasks, start=1):
        assert f"{k}. {squeeze(task)}" in text
    assert re.search(r"The mechanism to scale \d+(\.\d+)?:\d+(\.\d+)?", text)
    assert squeeze(variant.subtitle) in text


def test_a_sheet_with_many_tasks_takes_two_pages_and_keeps_them_all(press):
    tasks = [f"Task {k}: " + "compute the reactions in every pair at every position of the table, " * 3
             for k in range(1, 16)]
    kwargs = {**press.kwargs(), "tasks": tasks}
    figures = sheet_figures(press.mechanism, **kwargs)
    assert len(figures) == 2
    assert squeeze(" ".join(t for fig in figures for t in figure_texts(fig, "task"))) == squeeze(" ".join(tasks))
    assert page_count(assignment_sheet(press.mechanism, **kwargs)) == 2
    # four times as many: the list of tasks is split between tasks over as many pages as it needs,
    # none left out, the numbering going on, and the drawing keeps its scale
    figures = sheet_figures(press.mechanism, **{**kwargs, "tasks": tasks * 4})
    assert len(figures) >= 4
    assert squeeze(" ".join(t for fig in figures for t in figure_texts(fig, "task"))) == squeeze(" ".join(tasks * 4))
    numbers = [t.get_text() for fig in figures for t in fig.texts if re.fullmatch(r"\d+\.", t.get_text())]
    assert numbers == [f"{k}." for k in range(1, 61)]
    assert figure_texts(figures[0], "scale") == figure_texts(sheet_figures(press.mechanism, **{**kwargs, "data": [],
                                                                                               "tasks": []})[0], "scale")


# -- the drawing is to scale -------------------------------------------------------------------------


def _drawing(fig):
    fig.canvas.draw()                      # the positions and limits the page is saved with
    return next(ax for ax in fig.axes if ax.get_label() == "drawing")


def _stated_scale(fig) -> float:
    """paper / real from the text "The mechanism to scale 1:5" on the page."""
    text = " ".join(figure_texts(fig, "scale"))
    paper, real = re.search(r"scale (\d+(?:\.\d+)?):(\d+(?:\.\d+)?)$", text).groups()
    return float(paper) / float(real)


def _pin(ax, name: str) -> np.ndarray:
    return next(np.asarray(p.center) for p in ax.patches if p.get_gid() == f"pair:{name}")


def _paper_inches(ax, p: np.ndarray, q: np.ndarray) -> float:
    """Distance between two data points on the page, inches (the axes' transform to the display,
    whose pixels are 1 / dpi inch)."""
    a, b = ax.transData.transform(np.array([p, q]))
    return float(np.hypot(*(a - b))) / ax.figure.dpi


def _arrow_points(ax, arrow) -> np.ndarray:
    """The vertices of an arrow as drawn (FancyArrowPatch.get_path: in data coordinates), without
    the placeholder vertex of a CLOSEPOLY code, which is not drawn."""
    ax.figure.canvas.draw()
    path = arrow.get_path()
    codes = path.codes if path.codes is not None else np.full(len(path.vertices), Path.LINETO)
    return np.asarray(path.vertices, float)[codes != Path.CLOSEPOLY]


def _drawn_points(ax) -> np.ndarray:
    """Every vertex of every line, patch and line collection, in data coordinates."""
    pts = []
    for artist in [*ax.lines, *ax.patches, *ax.collections]:
        if isinstance(artist, FancyArrowPatch):
            pts.append(_arrow_points(ax, artist))
        elif isinstance(artist, Line2D):
            pts.append(np.asarray(artist.get_xydata(), float))
        elif isinstance(artist, Patch):
            pts.append(artist.get_path().transformed(artist.get_patch_transform()).vertices)
        elif isinstance(artist, LineCollection) and artist.get_segments():
            pts.append(np.vstack(artist.get_segments()))
    pts = np.vstack(pts)
    return pts[np.all(np.isfinite(pts), axis=1)]


@pytest.fixture(scope="module")
def cases(request):
    """name -> (page 1 of the sheet as a figure, {(pair, pair): distance in m}), made once."""
    made = {}

    def case(name):
        if name not in made:
            made[name] = _sheet_case(name, request)
        return made[name]

    return case


def _sheet_case(name, request):
    if name == "tiny":
        mech = tiny_four_bar()
        fig = sheet_figures(mech, title="Tiny four-bar", data=[("crank OA", "0.001", "m")],
                            tasks=["Measure AB"], position=3)[0]
        return fig, {("O", "A"): 1e-3, ("O", "C"): 3e-3, ("C", "B"): 2.5e-3}
    variant = request.getfixturevalue(name)
    fig = sheet_figures(variant.mechanism, **variant.kwargs())[0]
    v = variant.values
    if name == "press":
        return fig, {("O", "A"): v["crank"], ("A", "B"): v["rod"]}
    return fig, {("O1", "A"): v["crank"], ("O3", "O1"): v["pivots"]}


@pytest.mark.parametrize("name", ["press", "shaper", "tiny"])
def test_lengths_on_paper_are_the_mechanism_s_at_the_stated_scale(name, cases):
    fig, lengths = cases(name)
    ax = _drawing(fig)
    scale = _stated_scale(fig)
    assert any(math.isclose(scale, s, rel_tol=1e-12) for s in STANDARD), scale
    for (p, q), metres in lengths.items():
        inches = _paper_inches(ax, _pin(ax, p), _pin(ax, q))
        assert inches * 25.4 / 1000 / metres == pytest.approx(scale, rel=1e-9), (p, q)
    # the same in x and in y, straight from the axes: mm of paper per mm of mechanism
    (x0, y0), (x1, y1) = ax.transData.transform([(0.0, 0.0), (1.0, 1.0)]) / fig.dpi * 0.0254
    assert (x1 - x0, y1 - y0) == (pytest.approx(scale, rel=1e-9), pytest.approx(scale, rel=1e-9))
    assert fig.get_size_inches() * 25.4 == pytest.approx([210, 297])


@pytest.mark.parametrize("name", ["press", "tiny"])
def test_the_scale_is_the_largest_standard_one_the_width_allows(name, cases):
    """Both drawings are limited by the page's width: at the next larger standard scale what is
    drawn, with the labels' margin at both sides, would be wider than the axes."""
    fig, _ = cases(name)
    ax = _drawing(fig)
    scale = _stated_scale(fig)
    larger = [s for s in STANDARD if s > scale * (1 + 1e-12)][-1]
    pts = _drawn_points(ax)
    width_m = pts[:, 0].max() - pts[:, 0].min()
    axes_width = ax.get_position().width * fig.get_figwidth()
    assert width_m * scale / 0.0254 + 2 * sheets.PAPER_MARGIN <= axes_width + 1e-9
    assert width_m * larger / 0.0254 + 2 * sheets.PAPER_MARGIN > axes_width


@pytest.mark.parametrize("name", ["press", "shaper", "tiny"])
def test_nothing_of_the_drawing_is_cut_off(name, cases):
    fig, _ = cases(name)
    ax = _drawing(fig)
    pts = _drawn_points(ax)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert np.all((pts[:, 0] >= x0) & (pts[:, 0] <= x1) & (pts[:, 1] >= y0) & (pts[:, 1] <= y1))
    frame = ax.get_window_extent()
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if (t.get_gid() or "").startswith("label:")]
    assert labels
    for text in labels:
        box = text.get_window_extent(renderer)
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
    page = fig.bbox
    for text in fig.texts:                                 # the text stays within the paper's margins
        box = text.get_window_extent(renderer)
        assert box.x0 >= 10 / 25.4 * fig.dpi and box.x1 <= page.x1 - 10 / 25.4 * fig.dpi, text.get_text()


def test_position_1_of_the_press_is_the_far_extreme_position_in_closed_form(press, cases):
    """O, A and B on one line (A between): the crank at asin(e / (OA + AB)) from the x axis."""
    fig, _ = cases("press")
    ax = _drawing(fig)
    v = press.values
    expected = math.degrees(math.asin(v["offset"] / (v["crank"] + v["rod"])))
    a = _pin(ax, "A") - _pin(ax, "O")
    assert math.degrees(math.atan2(a[1], a[0])) == pytest.approx(expected, abs=1e-7)
    caption = " ".join(figure_texts(fig, "caption"))
    assert f"φ = {expected:.1f}°" in caption and "Position 1 of 12:" in caption
    assert "clockwise" in caption and "counter-clockwise" not in caption       # mean_rpm = -rpm
    arrow = next(p for p in ax.patches if p.get_gid() == "rotation-arrow")
    path = _arrow_points(ax, arrow)
    start, end = path[0] - _pin(ax, "O"), path[len(path) // 2] - _pin(ax, "O")   # the tail's end, the head
    assert start[0] * end[1] - start[1] * end[0] < 0                                # drawn clockwise


def test_a_tiny_mechanism_without_dynamics_is_drawn_at_the_table_position_asked(cases):
    """No [dynamics] and no output: 12 steps counter-clockwise from 0 deg; index 3 is 90 deg."""
    fig, _ = cases("tiny")
    ax = _drawing(fig)
    a = _pin(ax, "A") - _pin(ax, "O")
    assert math.degrees(math.atan2(a[1], a[0])) == pytest.approx(90.0, abs=1e-9)
    caption = " ".join(figure_texts(fig, "caption"))
    assert "Position 4 of 12:" in caption and "φ = 90.0°" in caption
    assert _stated_scale(fig) > 1                                               # an enlargement


def test_standard_scale_in_closed_form():
    # 0.45 m: at 1:2.5 it is 180 mm = 7.09 in, wider than 6.4 in; at 1:4 112.5 mm = 4.43 in
    assert standard_scale((0.45, 0.2), (6.4, 4.0)) == (1.0, 4.0)
    # 1 m high in 4 in = 101.6 mm of paper: 1:10 fits (100 mm), 1:5 does not
    assert standard_scale((0.3, 1.0), (6.4, 4.0)) == (1.0, 10.0)
    assert standard_scale((0.254, 0.1), (1.0, 1.0)) == (1.0, 10.0)          # exactly 1 in at 1:10
    assert standard_scale((0.003, 0.001), (6.4, 4.0)) == (50.0, 1.0)        # 150 mm
    assert standard_scale((40.0, 10.0), (6.4, 4.0)) == (1.0, 250.0)         # 160 mm
    assert sheets.scale_text((1.0, 2.5)) == "1:2.5" and sheets.scale_text((5.0, 1.0)) == "5:1"
    for bad in [(0.0, 1.0), (float("nan"), 1.0), (-1.0, 1.0)]:
        with pytest.raises(InputError, match="finite and > 0"):
            standard_scale(bad, (6.4, 4.0))


# -- the overview --------------------------------------------------------------------------------------


def _overview_input(rows: int = 80, columns: int = 12):
    header = ["variant"] + [f"param_{k}" for k in range(1, columns - 1)] + ["stroke, m"]
    table = [[str(i)] + [f"{0.005 * (i + k):.4g}" for k in range(1, columns - 1)] + [f"{0.1 + i / 1000:.4f}"]
             for i in range(1, rows + 1)]
    notes = ["min_transmission_angle_deg rejected 17 draws", "stroke rejected 4 draws"]
    return header, table, notes


def test_the_overview_of_80_variants_has_3_pages_each_with_the_header():
    header, rows, notes = _overview_input()
    expected_pages = math.ceil(80 / ROWS_PER_PAGE)                 # 35 + 35 + 10 rows, the notes after them
    assert ROWS_PER_PAGE == 35 and expected_pages == 3
    figures = overview_figures(title="Variants of press_slider_crank", header=header, rows=rows, notes=notes)
    assert len(figures) == expected_pages
    first_cells = []
    for k, fig in enumerate(figures, start=1):
        assert squeeze(" ".join(figure_texts(fig, "header"))) == squeeze(" ".join(header))
        assert figure_texts(fig, "page-number") == [f"page {k} of {expected_pages}"]
        cells = figure_texts(fig, "cell")
        assert len(cells) == len(header) * min(ROWS_PER_PAGE, 80 - ROWS_PER_PAGE * (k - 1))
        first_cells.append(cells[0])
    assert first_cells == ["1", "36", "71"]
    assert figure_texts(figures[-1], "note") == notes
    pdf = overview_pdf(title="Variants of press_slider_crank", header=header, rows=rows, notes=notes)
    assert page_count(pdf) == expected_pages
    boxes = media_boxes(pdf)
    assert len(boxes) == 3 and all(b == pytest.approx(A4_PT[::-1], abs=0.01) for b in boxes)   # landscape
    if shutil.which("pdftotext"):
        for k in range(1, expected_pages + 1):
            text = pdf_text(pdf, k)
            assert all(h in text for h in header) and f"page {k} of 3" in text
            assert ("Notes" in text) == (k == 3)
        assert all(n in pdf_text(pdf, 3) for n in notes)
        assert all(f" {r[0]} {r[1]} " in pdf_text(pdf) for r in rows)


def test_a_narrow_overview_is_portrait_and_long_notes_get_pages_of_their_own():
    rows = [[str(i), f"0.{i:03d}"] for i in range(1, 11)]
    notes = [f"note {k}: the rule number {k} rejected {3 * k} draws" for k in range(110)]
    figures = overview_figures(title="Narrow", header=["variant", "crank, m"], rows=rows, notes=notes)
    pages = len(figures)
    assert pages >= 3
    assert all(figure_texts(fig, "page-number") == [f"page {k} of {pages}"] for k, fig in enumerate(figures, 1))
    assert squeeze(" ".join(t for fig in figures for t in figure_texts(fig, "note"))) == squeeze(" ".join(notes))
    pdf = overview_pdf(title="Narrow", header=["variant", "crank, m"], rows=rows, notes=notes)
    assert page_count(pdf) == pages
    assert all(b == pytest.approx(A4_PT, abs=0.01) for b in media_boxes(pdf))           # portrait


# -- reproducible bytes -------------------------------------------------------------------------------

RENDER = textwrap.dedent("""
    import hashlib, sys
    sys.path.insert(0, "tests")
    from test_sheets import PRESS_FREE, Variant, assignment_sheet, overview_pdf, OVERVIEW
    press = Variant("press_slider_crank", PRESS_FREE)
    sheet = assignment_sheet(press.mechanism, **press.kwargs())
    print(hashlib.sha256(sheet).hexdigest(), hashlib.sha256(overview_pdf(**OVERVIEW)).hexdigest())
""")
OVERVIEW = dict(title="All", header=["variant", "crank, m"], rows=[[str(i), f"{i / 100}"] for i in range(40)],
                notes=["a note"])


def test_the_same_input_gives_the_same_bytes_in_another_process_directory_time_and_rc(tmp_path, press_pdf):
    first = [hashlib.sha256(press_pdf).hexdigest(), hashlib.sha256(overview_pdf(**OVERVIEW)).hexdigest()]
    time.sleep(1.1)
    rc = tmp_path / "matplotlibrc"
    rc.write_text("figure.dpi: 300\nfont.size: 14\npdf.fonttype: 3\nlines.linewidth: 4\nfont.family: serif\n")
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "tests").mkdir(parents=True)
    shutil.copy(FilePath(__file__), elsewhere / "tests" / "test_sheets.py")
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT), "HOME": str(tmp_path), "SOURCE_DATE_EPOCH": "1700000000",
           "MATPLOTLIBRC": str(rc), "MPLCONFIGDIR": matplotlib.get_configdir()}
    done = subprocess.run([sys.executable, "-c", RENDER], cwd=elsewhere, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == first


def test_the_pdf_has_no_dates_and_fixed_metadata(press_pdf):
    assert b"CreationDate" not in press_pdf and b"ModDate" not in press_pdf
    assert b"linkage" in press_pdf and b"Matplotlib v" not in press_pdf
    digest = hashlib.sha256(press_pdf).hexdigest()
    assert len(digest) == 64


# -- errors --------------------------------------------------------------------------------------------


def test_wrong_input_is_an_error_that_names_it(press):
    kwargs = press.kwargs()
    with pytest.raises(InputError, match=r"data row 2 must be three strings"):
        sheet_figures(press.mechanism, **{**kwargs, "data": [("a", "1", "m"), ("b", "2")]})
    with pytest.raises(InputError, match=r"position must be an index of its table of 13 positions.*got 13"):
        sheet_figures(press.mechanism, **kwargs, position=13)
    with pytest.raises(InputError, match="title"):
        assignment_sheet(press.mechanism, **{**kwargs, "title": " "})
    with pytest.raises(InputError, match=r"overview row 2 must be 2 strings"):
        overview_pdf(title="T", header=["a", "b"], rows=[["1", "2"], ["3"]])
    with pytest.raises(InputError, match=r"overview row 1 must be 2 strings"):
        overview_pdf(title="T", header=["a", "b"], rows=[["1", 2.0]])


def test_without_matplotlib_the_sheets_say_what_to_install(monkeypatch, press):
    for module in [m for m in list(sys.modules) if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, module, None)
    calls = [lambda: assignment_sheet(press.mechanism, **press.kwargs()),
             lambda: overview_pdf(title="T", header=["a"], rows=[["1"]])]
    for call in calls:
        with pytest.raises(PlotExtraMissing, match=re.escape('pip install "linkage[plot]"')) as info:
            call()
        assert isinstance(info.value, LinkageError) and isinstance(info.value, ImportError)
