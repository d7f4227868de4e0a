"""Writers of a drawing: PDF and SVG (matplotlib) and DXF (ezdxf), all from the same geometry.

Every writer draws the primitives of a :class:`~.model.Drawing` at their paper positions in mm:
the PDF page and the SVG are the paper's size, the DXF is in millimetres (``$INSUNITS = 4``)
with one DXF layer per :data:`~.model.LAYERS` entry. A primitive's width is its own; the model's
default width (``Line``/``Circle`` 0.35 mm, ``Arrow`` 0.5 mm) stands for its layer's width
(:data:`LAYER_STYLES`: outline and links 0.7, positions 0.25, trajectories 0.35 dashed, plans,
forces and diagrams 0.5, dimensions 0.25, the frame 1.0). A text's height is the height of its
capitals. An arrow is its shaft up to the head and a filled triangle ``head`` mm long (a DXF
SOLID); a filled circle is a CIRCLE and a solid HATCH.

PDF and SVG need matplotlib, DXF needs ezdxf, both in the ``report`` extra.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
import re
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ...report.folder import ReportExtraMissing
from .model import LAYERS, Arrow, Circle, Drawing, Line, Text

__all__ = [
    "FORMATS",
    "LAYER_STYLES",
    "LayerStyle",
    "arrow_head",
    "text_lines",
    "width_of",
    "write",
    "write_dxf",
    "write_pdf_svg",
]

FORMATS = ("pdf", "dxf", "svg")
_MM_TO_PT = 72.0 / 25.4
#: the height of DejaVu Sans's capitals as a fraction of the font size (1493 / 2048 units)
_CAP_HEIGHT = 0.729
#: dash and gap of a dashed line, mm
DASH = (5.0, 2.0)
_DXF_DASHED = "DASHED_5_2"
_FONT_FILE = "DejaVuSans.ttf"


@dataclass(frozen=True)
class LayerStyle:
    """How a layer is drawn: line width (mm), dashed or not, the DXF colour (AutoCAD index)."""

    width: float
    dashed: bool = False
    colour: int = 7


#: the style of each layer
LAYER_STYLES = {
    "frame": LayerStyle(1.0),
    "outline": LayerStyle(0.7),
    "links": LayerStyle(0.7),
    "positions": LayerStyle(0.25, colour=8),
    "trajectories": LayerStyle(0.35, dashed=True, colour=3),
    "plans": LayerStyle(0.5, colour=5),
    "forces": LayerStyle(0.5, colour=1),
    "diagrams": LayerStyle(0.5, colour=6),
    "dimensions": LayerStyle(0.25, colour=4),
    "text": LayerStyle(0.35),
}
assert set(LAYER_STYLES) == set(LAYERS)

_DEFAULT_WIDTHS = {kind: next(f.default for f in dataclasses.fields(kind) if f.name == "width")
                   for kind in (Line, Circle, Arrow)}


def width_of(item) -> float:
    """The drawn width (mm) of a line, circle or arrow: its own, or its layer's when it has
    the model's default."""
    if item.width == _DEFAULT_WIDTHS[type(item)]:
        return LAYER_STYLES[item.layer].width
    return float(item.width)


def _dashed(item) -> bool:
    return bool(getattr(item, "dashed", False)) or LAYER_STYLES[item.layer].dashed


def arrow_head(arrow: Arrow) -> tuple[tuple[float, float], tuple[tuple[float, float], ...]]:
    """The shaft's end (the head's base, mm) and the head's triangle (tip first) of ``arrow``:
    ``head`` mm long (at most the arrow's length), a third of that wide."""
    (xs, ys), (xe, ye) = arrow.start, arrow.end
    length = arrow.length
    if length == 0.0:
        return (xe, ye), ((xe, ye),) * 3
    ux, uy = (xe - xs) / length, (ye - ys) / length
    head = min(arrow.head, length)
    bx, by = xe - head * ux, ye - head * uy
    half = head / 6.0
    return (bx, by), ((xe, ye), (bx - half * uy, by + half * ux), (bx + half * uy, by - half * ux))


def text_lines(text: Text) -> list[tuple[str, tuple[float, float]]]:
    """Each line of ``text`` with its anchor point (mm) on its baseline, lines 1.6 heights
    apart, turned with the text about ``text.at`` (horizontal alignment as ``text.anchor``)."""
    lines = text.text.split("\n")
    h = text.height
    tall = h * (1.6 * len(lines) - 0.6)
    top = {"bottom": tall, "middle": tall / 2, "top": 0.0}[text.anchor[1]]
    a = math.radians(text.angle)
    out = []
    for i, line in enumerate(lines):
        y = top - h - 1.6 * h * i
        out.append((line, (text.at[0] - y * math.sin(a), text.at[1] + y * math.cos(a))))
    return out


def write(drawing: Drawing, stem: Path, formats=FORMATS) -> list[Path]:
    """Write ``drawing`` as ``stem.pdf``, ``stem.dxf``, ``stem.svg`` (those of ``formats``, in
    that order); creates the folder. Returns the files written.

    Raises :class:`~linkage.errors.InputError` for an unknown format and
    :class:`~linkage.report.folder.ReportExtraMissing` when matplotlib (PDF, SVG) or ezdxf (DXF)
    is not installed.
    """
    formats = [f.lower().lstrip(".") for f in formats]
    unknown = [f for f in formats if f not in FORMATS]
    if unknown:
        raise InputError(f"unknown drawing format {', '.join(map(repr, unknown))} (one of {', '.join(FORMATS)})")
    stem = Path(stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for fmt in FORMATS:
        if fmt not in formats:
            continue
        path = stem.parent / f"{stem.name}.{fmt}"
        if fmt == "dxf":
            write_dxf(drawing, path)
        else:
            write_pdf_svg(drawing, path)
        written.append(path)
    return written


def _require(module: str, what: str) -> None:
    if importlib.util.find_spec(module) is None:
        raise ReportExtraMissing(f"{what} needs the 'report' extra ({module} missing): "
                                 "pip install \"linkage[report]\"")


def write_pdf_svg(drawing: Drawing, path: Path) -> Path:
    """Write ``drawing`` to ``path`` (``.pdf`` or ``.svg``) through matplotlib: a figure of
    the paper's size, one axes covering it in mm; an SVG states its width and height in mm."""
    path = Path(path)
    _require("matplotlib", f"writing {path.name}")
    import matplotlib
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle as CirclePatch
    from matplotlib.patches import Polygon

    width_mm, height_mm = drawing.size
    with matplotlib.rc_context({"font.family": "DejaVu Sans", "pdf.fonttype": 42, "svg.fonttype": "path",
                                "lines.solid_capstyle": "round", "lines.dash_capstyle": "butt",
                                "svg.hashsalt": "linkage"}):
        fig = Figure(figsize=(width_mm / 25.4, height_mm / 25.4))
        ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_xlim(0.0, width_mm)
        ax.set_ylim(0.0, height_mm)
        ax.set_axis_off()
        for item in drawing.items:
            if isinstance(item, Text):
                for line, (x, y) in text_lines(item):
                    ax.text(x, y, line, fontsize=item.height / _CAP_HEIGHT * _MM_TO_PT, ha=item.anchor[0],
                            va="baseline", rotation=item.angle, rotation_mode="anchor", color="black",
                            parse_math=False)
                continue
            lw = width_of(item) * _MM_TO_PT
            if isinstance(item, Line):
                xs = [p[0] for p in item.points] + ([item.points[0][0]] if item.closed else [])
                ys = [p[1] for p in item.points] + ([item.points[0][1]] if item.closed else [])
                style = {"dashes": (DASH[0] * _MM_TO_PT / lw, DASH[1] * _MM_TO_PT / lw)} if _dashed(item) else {}
                ax.plot(xs, ys, color="black", linewidth=lw, solid_joinstyle="miter" if item.closed else "round",
                        **style)
            elif isinstance(item, Circle):
                ax.add_patch(CirclePatch(item.centre, item.radius, linewidth=lw, edgecolor="black",
                                         facecolor="black" if item.filled else "none"))
            elif isinstance(item, Arrow):
                base, head = arrow_head(item)
                ax.plot([item.start[0], base[0]], [item.start[1], base[1]], color="black", linewidth=lw,
                        solid_capstyle="butt")
                ax.add_patch(Polygon(head, closed=True, facecolor="black", edgecolor="none"))
        metadata = {"Title": drawing.title or "sheet", "Creator": "linkage"}
        fig.savefig(path, format=path.suffix.lstrip(".").lower(), metadata=metadata)
    if path.suffix.lower() == ".svg":
        text = path.read_text(encoding="utf-8")
        text = re.sub(r'(<svg[^>]*?)width="[^"]*"\s+height="[^"]*"',
                      lambda m: f'{m.group(1)}width="{width_mm:g}mm" height="{height_mm:g}mm"', text, count=1)
        path.write_text(text, encoding="utf-8")
    return path


def _lineweight(width_mm: float) -> int:
    """The DXF lineweight (1/100 mm, a standard value) nearest ``width_mm``."""
    from ezdxf.lldxf.const import VALID_DXF_LINEWEIGHTS
    return min(VALID_DXF_LINEWEIGHTS, key=lambda w: abs(w - 100 * width_mm))


_DXF_ALIGN = {("left", "bottom"): "LEFT", ("center", "bottom"): "CENTER", ("right", "bottom"): "RIGHT"}
_MTEXT_ATTACH = {("left", "top"): 1, ("center", "top"): 2, ("right", "top"): 3, ("left", "middle"): 4,
                 ("center", "middle"): 5, ("right", "middle"): 6, ("left", "bottom"): 7, ("center", "bottom"): 8,
                 ("right", "bottom"): 9}


def write_dxf(drawing: Drawing, path: Path) -> Path:
    """Write ``drawing`` to ``path`` as DXF R2010 in mm: LWPOLYLINE for lines, CIRCLE (+ solid
    HATCH when filled), an arrow as an LWPOLYLINE shaft and a SOLID head, TEXT for a one-line
    text (MTEXT for several lines) with its height; each entity on its model layer."""
    path = Path(path)
    _require("ezdxf", f"writing {path.name}")
    import ezdxf
    from ezdxf import units
    from ezdxf.enums import TextEntityAlignment

    doc = ezdxf.new("R2010")
    doc.units = units.MM
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LWDISPLAY"] = 1
    doc.header["$LIMMIN"] = (0.0, 0.0)
    doc.header["$LIMMAX"] = drawing.size
    doc.linetypes.add(_DXF_DASHED, pattern=[DASH[0] + DASH[1], DASH[0], -DASH[1]], description="dashed 5 mm, gap 2 mm")
    doc.styles.new("DejaVu", dxfattribs={"font": _FONT_FILE})
    for name in LAYERS:
        style = LAYER_STYLES[name]
        doc.layers.add(name, color=style.colour, lineweight=_lineweight(style.width),
                       linetype=_DXF_DASHED if style.dashed else "Continuous")
    msp = doc.modelspace()
    for item in drawing.items:
        attribs = {"layer": item.layer}
        if isinstance(item, Text):
            attribs["style"] = "DejaVu"
            if "\n" in item.text:
                mtext = msp.add_mtext(item.text, dxfattribs={**attribs, "char_height": item.height,
                                                            "rotation": item.angle,
                                                            "attachment_point": _MTEXT_ATTACH[item.anchor],
                                                            "line_spacing_factor": 1.6 / (5.0 / 3.0)})
                mtext.dxf.insert = item.at
            else:
                text = msp.add_text(item.text, height=item.height, rotation=item.angle, dxfattribs=attribs)
                align = _DXF_ALIGN.get(item.anchor, f"{item.anchor[1].upper()}_{item.anchor[0].upper()}")
                text.set_placement(item.at, align=TextEntityAlignment[align])
            continue
        attribs["lineweight"] = _lineweight(width_of(item))
        if isinstance(item, Line):
            if item.dashed and not LAYER_STYLES[item.layer].dashed:
                attribs["linetype"] = _DXF_DASHED
            msp.add_lwpolyline(item.points, format="xy", close=item.closed, dxfattribs=attribs)
        elif isinstance(item, Circle):
            msp.add_circle(item.centre, item.radius, dxfattribs=attribs)
            if item.filled:
                hatch = msp.add_hatch(dxfattribs={"layer": item.layer})
                hatch.set_solid_fill(color=256)
                hatch.paths.add_edge_path().add_arc(item.centre, item.radius, 0.0, 360.0)
        elif isinstance(item, Arrow):
            base, head = arrow_head(item)
            msp.add_lwpolyline([item.start, base], format="xy", dxfattribs=attribs)
            msp.add_solid(head, dxfattribs={"layer": item.layer})
    doc.saveas(path)
    return path
