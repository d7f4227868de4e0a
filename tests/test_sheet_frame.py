"""The sheets' frame, title block, tables, layout checks and writers (linkage.course.project).

Oracles: standard scales worked out by hand; the drafting layout's numbers (frame 20/5 mm, title
block 185 x 55 mm); DejaVu Sans's own glyph outlines for the real width of the title block's
texts; the DXF read back with ezdxf; the PDF's page size from poppler's pdfinfo.
"""

from __future__ import annotations

import itertools
import math
import re
import shutil
import subprocess

import numpy as np
import pytest

from linkage.course.project import writers
from linkage.course.project.frame import (
    TitleInfo,
    blank_sheet,
    layout_problems,
    scales_table,
    table,
)
from linkage.course.project.model import (
    PAPERS,
    STANDARD_MANTISSAS,
    Arrow,
    Circle,
    Line,
    Scale,
    Text,
    standard_scale,
)
from linkage.errors import InputError

TITLE = TitleInfo(scheme="course_slider_crank", variant="12", student="Ivanov I. I.", group="MT-21-3")


# ---- standard scales ---------------------------------------------------------------------------

@pytest.mark.parametrize("longest, expected", [
    (0.37, 0.004),      # 0.37/0.004 = 92.5 mm; 0.0025 draws 148 mm (too long)
    (150.0, 2.0),       # 150/2 = 75 mm; 1 draws 150 mm
    (7.0, 0.1),         # 70 mm; 0.05 draws 140 mm
    (1000.0, 10.0),     # 100 mm; 5 draws 200 mm
    (0.0123, 0.0002),   # 61.5 mm; 1e-4 draws 123 mm
    (61.0, 1.0),        # 61 mm; 0.5 draws 122 mm
    (240.0, 2.0),       # 120 mm exactly, the range's upper end
    (0.06, 0.0005),     # 120 mm (0.001 draws 60 mm, also in range: the larger drawing wins)
])
def test_standard_scale_by_hand(longest, expected):
    assert standard_scale(longest, 60, 120) == pytest.approx(expected, rel=1e-12)


def test_standard_scale_always_draws_60_to_120_mm_as_large_as_possible():
    rng = np.random.default_rng(22)
    for longest in 10.0 ** rng.uniform(-5, 5, 300):
        scale = standard_scale(longest, 60, 120)
        exponent = math.floor(math.log10(scale))
        mantissa = scale / 10.0 ** exponent
        assert any(math.isclose(mantissa, m, rel_tol=1e-9) for m in STANDARD_MANTISSAS + (10.0,)), scale
        assert 60 - 1e-9 <= longest / scale <= 120 + 1e-9, (longest, scale)
        finer = max(m * 10.0 ** e for e in (exponent - 1, exponent) for m in STANDARD_MANTISSAS
                    if m * 10.0 ** e < scale * (1 - 1e-9))
        assert longest / finer > 120, (longest, scale, finer)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_standard_scale_refuses_a_length_that_is_not_positive(bad):
    with pytest.raises(ValueError):
        standard_scale(bad)


# ---- the blank sheet and its title block ---------------------------------------------------------

def _segments(drawing):
    """The title block's and frame's rules as segments ((x0, y0), (x1, y1))."""
    out = []
    for item in drawing.items:
        if isinstance(item, Line) and item.layer == "frame":
            pts = list(item.points) + ([item.points[0]] if item.closed else [])
            out += list(itertools.pairwise(pts))
    return out


def _crosses(box, segment) -> bool:
    """Whether an axis-parallel segment passes through the inside of ``box``."""
    (xa, ya), (xb, yb) = segment
    x0, y0, x1, y1 = box
    if ya == yb:
        return y0 < ya < y1 and min(xa, xb) < x1 and max(xa, xb) > x0
    return x0 < xa < x1 and min(ya, yb) < y1 and max(ya, yb) > y0


def _real_width(text: Text) -> float:
    """The widest line of ``text`` drawn in DejaVu Sans with capitals ``height`` mm tall, mm
    (measured on the font's outlines: the capital H gives the cap height)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath
    font = FontProperties(family="DejaVu Sans")
    cap = TextPath((0, 0), "H", size=1.0, prop=font).get_extents().height
    return max(TextPath((0, 0), line, size=text.height / cap, prop=font).get_extents().x1
               for line in text.text.split("\n"))


@pytest.mark.parametrize("paper", ["A1", "A2", "A3"])
def test_blank_sheet_frame_and_title_block(paper):
    drawing, free = blank_sheet(paper, TITLE, "Kinematic analysis", 2, 3)
    width, height = PAPERS[paper]
    assert free == (20.0, 5.0, width - 5.0, height - 5.0)
    regions = {r.name: r.box for r in drawing.regions}
    assert regions["frame"] == free
    assert regions["title block"] == (width - 5.0 - 185.0, 5.0, width - 5.0, 60.0)
    assert layout_problems(drawing) == []
    texts = [t.text.replace("\n", " ") for t in drawing.items if isinstance(t, Text)]
    for wanted in ("Course project: theory of machines and mechanisms", "Scheme: course_slider_crank", "12",
                   "Kinematic analysis", "Sheet 2 of 3", "Ivanov I. I.", "Group MT-21-3", paper, "Date", "Student"):
        assert wanted in texts, (wanted, texts)


@pytest.mark.parametrize("title, name", [
    (TITLE, "Kinematic analysis"),
    (TitleInfo(scheme="six-bar with a slotted link and a rocker, second variant of the assignment", variant="123",
               student="Konstantinopolskaya Aleksandra", group="TMM-2024-17b"),
     "Kinetostatic analysis of the mechanism in position 7"),
])
def test_title_block_texts_stay_in_their_cells(title, name):
    drawing, _ = blank_sheet("A1", title, name, 3, 3)
    block = next(r.box for r in drawing.regions if r.name == "title block")
    rules = _segments(drawing)
    texts = [t for t in drawing.items if isinstance(t, Text)]
    assert texts
    for t in texts:
        assert 2.5 <= t.height <= 5.0, t
        x0, y0, x1, y1 = t.box()
        assert block[0] < x0 and x1 < block[2] and block[1] < y0 and y1 < block[3], t
        assert not any(_crosses((x0, y0, x1, y1), s) for s in rules), t
        # the width DejaVu Sans really draws, about the text's anchor, stays in the cell too
        real = _real_width(t)
        left = {"left": t.at[0], "center": t.at[0] - real / 2, "right": t.at[0] - real}[t.anchor[0]]
        assert not any(_crosses((left, y0, left + real, y1), s) for s in rules), (t, real)


def test_title_block_date_column_is_blank():
    drawing, _ = blank_sheet("A2", TITLE, "Dynamics", 3, 3)
    x1 = drawing.size[0] - 5.0
    in_date_column = [t.text for t in drawing.items if isinstance(t, Text)
                      and x1 - 185 + 55 < t.at[0] < x1 - 185 + 65 and t.at[1] < 5 + 25]
    assert in_date_column == []


def test_the_title_numbers_the_sheet_when_it_says_so():
    drawing, _ = blank_sheet("A3", TitleInfo(number=2, total=2), "Dynamics", 3, 3)
    texts = [t.text for t in drawing.items if isinstance(t, Text)]
    assert "Sheet 2 of 2" in texts and "Sheet 3 of 3" not in texts


def test_a_sheet_number_beyond_the_total_is_refused():
    with pytest.raises(ValueError, match="4 of 3"):
        blank_sheet("A1", TITLE, "Dynamics", 4, 3)


# ---- the layout checks ----------------------------------------------------------------------------

def test_layout_problems_reports_what_a_teacher_would_reject():
    drawing, _ = blank_sheet("A3", TITLE, "Kinematic analysis", 1, 3)
    drawing.add(Text((300.0, 20.0), "over the block", height=3.5))
    drawing.add(Text((5.0, 150.0), "in the binding margin", height=3.5))
    drawing.add(Line(((100.0, 100.0), (100.0, 295.0)), layer="links"))
    drawing.add(Text((100.0, 200.0), "first", height=5.0))
    drawing.add(Text((105.0, 201.0), "second", height=5.0))
    problems = layout_problems(drawing)
    assert "'over the block'" in problems[0] and "lies over the title block" in problems[0]
    assert "'in the binding margin'" in problems[1] and "outside the frame" in problems[1]
    assert "line on the 'links' layer" in problems[2] and "outside the frame" in problems[2]
    assert any("'first'" in p and "'second'" in p and "overlap" in p for p in problems), problems
    # the rest: the text over the block also covers the block's own texts
    assert all("'over the block'" in p for p in problems[3:] if "'first'" not in p), problems


def test_layout_problems_reports_regions_overlapping_and_turned_texts():
    drawing, _ = blank_sheet("A2", TITLE, "Kinematic analysis", 1, 3)
    table(drawing, (30.0, 400.0), ["a"], [["1"]], [20.0], name="first table")
    table(drawing, (40.0, 395.0), ["b"], [["2"]], [20.0], name="second table")
    # a text turned 90 degrees rises from its anchor: 40 characters x 0.7 x 5 mm = 140 mm up
    drawing.add(Text((300.0, 300.0), "x" * 40, height=5.0, angle=90.0))
    problems = layout_problems(drawing)
    assert any("'first table'" in p and "'second table'" in p and "overlap" in p for p in problems), problems
    assert any("'xxxx" in p and "outside the frame" in p for p in problems), problems
    assert any("'1'" in p and "'b'" in p and "overlap" in p for p in problems), problems
    assert len(problems) == 3, problems   # the two regions, the turned text, two tables' texts


# ---- tables ---------------------------------------------------------------------------------------

def test_table_box_and_cells():
    drawing, _ = blank_sheet("A1", TITLE, "Kinematic analysis", 1, 3)
    box = table(drawing, (100.0, 500.0), ["Quantity", "Plan", "Δ, %"], [["v_B, m/s", "1.234", "0.3"],
                                                                       ["ω_2, rad/s", "−4.56", "0.2"]],
                [40.0, 30.0, 20.0], height=3.5)
    # a row is 2 x 3.5 + 1 = 8 mm: the header and two rows are 24 mm; the columns 90 mm
    assert box == pytest.approx((100.0, 476.0, 190.0, 500.0))
    assert next(r.box for r in drawing.regions if r.name == "table") == pytest.approx(box)
    cells = {t.text: t for t in drawing.items if isinstance(t, Text) and t.layer == "text"}
    assert cells["1.234"].anchor[0] == "right" and cells["v_B, m/s"].anchor[0] == "left"
    assert cells["−4.56"].at[1] == pytest.approx(476.0 + 4.0)       # middle of the last row
    assert layout_problems(drawing) == []


@pytest.mark.parametrize("header, rows, widths, match", [
    (["a", ""], [["1", "2"]], [20.0, 20.0], "heading"),
    (["a", "b"], [["1"]], [20.0, 20.0], "1 cells for 2 columns"),
    (["a"], [["a long cell text"]], [20.0], "needs"),
])
def test_table_refuses_a_column_without_heading_or_a_cell_too_wide(header, rows, widths, match):
    drawing, _ = blank_sheet("A3", TITLE, "Kinematic analysis", 1, 3)
    with pytest.raises(ValueError, match=match):
        table(drawing, (30.0, 200.0), header, rows, widths)


def test_scales_table_lists_each_scale_once():
    drawing, _ = blank_sheet("A1", TITLE, "Kinematic analysis", 1, 3)
    drawing.view(Scale("μ_l", 0.002, "m/mm"))
    drawing.view(Scale("μ_v", 0.02, "(m/s)/mm"))
    drawing.use(Scale("μ_l", 0.002, "m/mm"))
    box = scales_table(drawing, (25.0, 589.0))
    texts = [t.text for t in drawing.items if isinstance(t, Text) and t.layer == "text"]
    assert texts == ["Scales", "μ_l = 0.002 m/mm", "μ_v = 0.02 (m/s)/mm"]
    assert box[3] == 589.0 and box[1] == pytest.approx(589.0 - 3 * 8.0)
    assert [r.name for r in drawing.regions][-1] == "scales"
    assert layout_problems(drawing) == []


# ---- writers --------------------------------------------------------------------------------------

def _sample(paper="A1"):
    drawing, _ = blank_sheet(paper, TITLE, "Kinematic analysis", 1, 3)
    view = drawing.view(Scale("μ_l", 0.002, "m/mm"), origin=(60.0, 200.0))
    view.line([(0.0, 0.0), (0.1, 0.1), (0.4, 0.0)], layer="links")
    view.line([(0.0, 0.0), (0.1, -0.1), (0.4, 0.0)], layer="positions", closed=True)
    view.line([(0.015 * i, 0.02 * (i % 3)) for i in range(20)], layer="trajectories")
    view.circle((0.0, 0.0), 1.5, layer="links", filled=True)
    view.circle((0.1, 0.1), 1.5, layer="links")
    drawing.add(Line(((150.0, 100.0), (210.0, 100.0)), layer="dimensions", width=0.5))
    drawing.add(Arrow((300.0, 100.0), (360.3, 131.7)))
    drawing.add(Arrow((300.0, 100.0), (280.0, 70.0), layer="forces", head=5.0))
    drawing.add(Text((330.0, 160.0), "pv = 68 mm\nμ_v = 0.02", height=5.0, anchor=("center", "top")))
    drawing.add(Text((40.0, 150.0), "turned", height=3.5, angle=90.0))
    scales_table(drawing, (25.0, drawing.size[1] - 5.0))
    assert layout_problems(drawing) == []
    return drawing


def _expected_entities(drawing):
    """What the DXF writer makes of each primitive, counted per layer and entity type."""
    counts: dict[tuple[str, str], int] = {}

    def add(layer, kind):
        counts[layer, kind] = counts.get((layer, kind), 0) + 1
    for item in drawing.items:
        if isinstance(item, Line):
            add(item.layer, "LWPOLYLINE")
        elif isinstance(item, Circle):
            add(item.layer, "CIRCLE")
            if item.filled:
                add(item.layer, "HATCH")
        elif isinstance(item, Arrow):
            add(item.layer, "LWPOLYLINE")
            add(item.layer, "SOLID")
        elif isinstance(item, Text):
            add(item.layer, "MTEXT" if "\n" in item.text else "TEXT")
    return counts


def test_dxf_has_the_model_geometry(tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    drawing = _sample()
    (path,) = writers.write(drawing, tmp_path / "sheet", formats=("dxf",))
    assert path == tmp_path / "sheet.dxf"
    doc = ezdxf.readfile(path)
    assert doc.header["$INSUNITS"] == 4
    assert {layer.dxf.name for layer in doc.layers} >= {"frame", "outline", "links", "positions", "trajectories",
                                                        "plans", "forces", "diagrams", "dimensions", "text"}
    entities = list(doc.modelspace())
    counts: dict[tuple[str, str], int] = {}
    for e in entities:
        counts[e.dxf.layer, e.dxftype()] = counts.get((e.dxf.layer, e.dxftype()), 0) + 1
    assert counts == _expected_entities(drawing)

    polylines = [e for e in entities if e.dxftype() == "LWPOLYLINE"]
    lines = [item for item in drawing.items if isinstance(item, Line)]
    arrows = [item for item in drawing.items if isinstance(item, Arrow)]
    # the writer keeps the model's order: a line's vertices are the model's points to 1e-6 mm
    line_polys = [e for e in polylines if len(e) != 2 or (e.dxf.layer not in ("plans", "forces"))]
    assert len(line_polys) == len(lines)
    for item, e in zip(lines, line_polys):
        assert e.dxf.layer == item.layer and bool(e.closed) == item.closed
        np.testing.assert_allclose(np.array(e.get_points("xy")), np.array(item.points), atol=1e-6)
    widths = {(item.layer, e.dxf.lineweight) for item, e in zip(lines, line_polys)}
    assert ("positions", 25) in widths and ("links", 70) in widths and ("dimensions", 50) in widths
    assert ("trajectories", 35) in widths
    assert doc.layers.get("trajectories").dxf.linetype != "Continuous"

    solids = [e for e in entities if e.dxftype() == "SOLID"]
    shafts = [e for e in polylines if e.dxf.layer in ("plans", "forces") and len(e) == 2]
    for arrow, solid, shaft in zip(arrows, solids, shafts, strict=True):
        tip = np.array(solid.dxf.vtx0)[:2]
        base = (np.array(solid.dxf.vtx1)[:2] + np.array(solid.dxf.vtx2)[:2]) / 2
        np.testing.assert_allclose(tip, arrow.end, atol=1e-6)
        np.testing.assert_allclose(np.linalg.norm(tip - base), arrow.head, atol=1e-6)
        np.testing.assert_allclose(np.array(shaft.get_points("xy"))[0], arrow.start, atol=1e-6)
        np.testing.assert_allclose(np.array(shaft.get_points("xy"))[1], base, atol=1e-6)

    circles = [item for item in drawing.items if isinstance(item, Circle)]
    for item, e in zip(circles, [e for e in entities if e.dxftype() == "CIRCLE"], strict=True):
        np.testing.assert_allclose(np.array(e.dxf.center)[:2], item.centre, atol=1e-6)
        assert e.dxf.radius == pytest.approx(item.radius, abs=1e-9)

    texts = [item for item in drawing.items if isinstance(item, Text)]
    written = [e for e in entities if e.dxftype() in ("TEXT", "MTEXT")]
    for item, e in zip(texts, written, strict=True):
        if e.dxftype() == "TEXT":
            assert e.dxf.text == item.text and e.dxf.height == pytest.approx(item.height, abs=1e-9)
            assert e.dxf.rotation == pytest.approx(item.angle)
        else:
            assert e.plain_text() == item.text and e.dxf.char_height == pytest.approx(item.height, abs=1e-9)


@pytest.mark.parametrize("paper", ["A1", "A3"])
def test_pdf_page_and_svg_are_the_paper_size(tmp_path, paper):
    pytest.importorskip("matplotlib")
    drawing = _sample(paper)
    pdf, svg = writers.write(drawing, tmp_path / "sheet", formats=("svg", "pdf"))
    assert (pdf.name, svg.name) == ("sheet.pdf", "sheet.svg")
    width, height = PAPERS[paper]
    root = re.search(r"<svg[^>]*>", svg.read_text(encoding="utf-8")).group(0)
    assert f'width="{width:g}mm"' in root and f'height="{height:g}mm"' in root
    view_box = [float(v) for v in re.search(r'viewBox="([^"]*)"', root).group(1).split()]
    assert view_box[2] / view_box[3] == pytest.approx(width / height, rel=1e-6)
    if shutil.which("pdfinfo") is None:
        pytest.skip("poppler's pdfinfo is not installed")
    info = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    w_pt, h_pt = map(float, re.search(r"Page size:\s+([\d.]+) x ([\d.]+) pts", info).groups())
    assert w_pt * 25.4 / 72 == pytest.approx(width, abs=0.1)
    assert h_pt * 25.4 / 72 == pytest.approx(height, abs=0.1)


def test_writer_refuses_an_unknown_format(tmp_path):
    with pytest.raises(InputError, match="'png'"):
        writers.write(_sample("A3"), tmp_path / "sheet", formats=("pdf", "png"))


def test_writer_names_the_extra_when_ezdxf_is_missing(tmp_path, monkeypatch):
    real = writers.importlib.util.find_spec
    monkeypatch.setattr(writers.importlib.util, "find_spec",
                        lambda name, *a: None if name == "ezdxf" else real(name, *a))
    with pytest.raises(ImportError, match=r'pip install "linkage\[report\]"'):
        writers.write(_sample("A3"), tmp_path / "sheet", formats=("dxf",))
    assert not (tmp_path / "sheet.dxf").exists()
