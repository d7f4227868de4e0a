"""The load diagrams of an assignment sheet: each a small labelled graph with its zones in words
and its table of values, typeset as one block of a page.

:func:`diagram_block` -- one diagram of ``given.json`` (:func:`linkage.course.given.load_diagrams`):
a force (N) or moment (N·m) over the fraction t of the working stroke (0 at its start, 1 at its
end; the idle stroke, when declared, to the right of it from 1 to 2), drawn as declared, jumps
and all, with every declared point marked; or a cycle table over the table positions. Beside the
graph the working direction, whether the load opposes the motion and the zones of the diagram
(``0.05 – 0.95: 2750 N``); under it the table of the declared values, a row of t and a row of
values, as the course writes such tables. Used by :mod:`~linkage.course.sheets`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .given import number_text, subscripted, unit_text, zone_text
from .typesetting import HEADING, SIDE, TABLE, Block, Measure, line_height, rule, shade, write

__all__ = ["diagram_block"]

#: the graph's axes on paper, inches: left margin (tick labels), width, height, room below (x label)
GRAPH_LEFT, GRAPH_WIDTH, GRAPH_HEIGHT, GRAPH_BELOW = 0.72, 3.3, 1.7, 0.42
#: gap between the graph and the words beside it, inches
BESIDE = 0.3
def _words(diagram: Mapping[str, Any]) -> list[str]:
    """What the graph means, in lines: the stroke, the sense, the zones."""
    name, unit = subscripted(diagram["name"]), unit_text(diagram["unit"])
    if diagram["kind"] == "cycle":
        along = f" along {diagram['along']}" if diagram.get("along") else " along its direction"
        return [(f"{name}{along}, signed, at the table positions 1 … {len(diagram['values'])} (linear between "
                 "them; the last position closes the cycle).")]
    coordinate = diagram["coordinate"]
    sense = "increasing (+)" if diagram["working"] == "+" else "decreasing (−)"
    lines = [(f"Working stroke: {coordinate} {sense}. t = the travel of {coordinate} from the start of the stroke "
              "over the whole stroke (0 at its start, 1 at its end).")]
    if diagram["signed"]:
        lines.append(f"{name} is signed along its direction.")
    elif diagram.get("opposes", True):
        lines.append(f"{name} opposes the motion (a useful resistance).")
    else:
        lines.append(f"{name} drives the motion.")
    for stroke in diagram["strokes"]:
        lines.append(f"Zones of the {stroke['stroke']} stroke (t: {name}):")
        lines += [f"  {zone_text(zone, unit)}" for zone in stroke["zones"]]
    if len(diagram["strokes"]) == 1:
        lines.append("Idle stroke: no load.")
    return lines


def _bands(diagram: Mapping[str, Any]) -> list[tuple[str, str, list[str], list[str]]]:
    """The rows of the table of values: (label of the x row, label of the value row, x, values)."""
    name, unit = subscripted(diagram["name"]), unit_text(diagram["unit"])
    if diagram["kind"] == "cycle":
        return [("position", f"{name}, {unit}", [str(p) for p in diagram["positions"]],
                 [number_text(v) for v in diagram["values"]])]
    return [(f"t, {stroke['stroke']} stroke", f"{name}, {unit}", [number_text(t) for t in stroke["fractions"]],
             [number_text(v) for v in stroke["values"]]) for stroke in diagram["strokes"]]


def diagram_block(measure: Measure, width: float, diagram: Mapping[str, Any]) -> Block:
    """One load diagram of ``given.json`` as a block: heading, graph, words, table of values."""
    heading = measure.wrap(f"{subscripted(diagram['name'])}: {diagram['title']}", width, HEADING, bold=True)
    text_width = width - GRAPH_LEFT - GRAPH_WIDTH - BESIDE
    words = [line for text in _words(diagram) for line in measure.wrap(text, text_width, TABLE)]
    graph = GRAPH_HEIGHT + GRAPH_BELOW
    top_part = len(heading) * line_height(HEADING) + 0.1
    body = max(graph, len(words) * line_height(TABLE))
    bands = _table_rows(measure, width, diagram)
    table = sum(2 * line_height(TABLE) + 0.12 for _ in bands)

    def draw(fig, top):
        write(fig, SIDE, top, "\n".join(heading), HEADING, bold=True, gid="diagram-heading")
        y = top - top_part
        _graph(fig, diagram, (SIDE + GRAPH_LEFT, y - GRAPH_HEIGHT - 0.05, GRAPH_WIDTH, GRAPH_HEIGHT))
        write(fig, SIDE + GRAPH_LEFT + GRAPH_WIDTH + BESIDE, y, "\n".join(words), TABLE, gid="diagram-words")
        y -= body + 0.08
        for label_x, label_v, xs, vs, widths in bands:
            y = _band(fig, y, label_x, label_v, xs, vs, widths)

    return Block(top_part + body + 0.08 + table, draw, gap=0.22)


def _table_rows(measure: Measure, width: float, diagram: Mapping[str, Any]):
    """The table's bands: as many columns per band as the width holds, (label x, label value,
    x texts, value texts, (label width, column width))."""
    found = []
    for label_x, label_v, xs, vs in _bands(diagram):
        label = max(measure.width(label_x, TABLE, True), measure.width(label_v, TABLE, True)) + 0.16
        column = max(measure.width(t, TABLE) for t in [*xs, *vs]) + 0.16
        per_band = max(1, int((width - label) // column))
        for k in range(0, len(xs), per_band):
            found.append((label_x, label_v, xs[k:k + per_band], vs[k:k + per_band], (label, column)))
    return found


def _band(fig, top: float, label_x: str, label_v: str, xs: list[str], vs: list[str], widths) -> float:
    """Two rows of the table of values from ``top`` (inches); the top of what comes next."""
    label, column = widths
    h = line_height(TABLE)
    right = SIDE + label + column * len(xs)
    shade(fig, SIDE, top - h - 0.02, right - SIDE, h + 0.02)
    rule(fig, SIDE, right, top, lw=0.6, colour="0.3")
    write(fig, SIDE + 0.06, top - 0.02, label_x, TABLE, bold=True)
    write(fig, SIDE + 0.06, top - h - 0.04, label_v, TABLE, bold=True)
    for k, (x, v) in enumerate(zip(xs, vs, strict=True)):
        left = SIDE + label + column * k
        write(fig, left + column - 0.08, top - 0.02, x, TABLE, ha="right", gid="diagram-x")
        write(fig, left + column - 0.08, top - h - 0.04, v, TABLE, ha="right", gid="diagram-value")
    rule(fig, SIDE, right, top - 2 * h - 0.06, lw=0.6, colour="0.3")
    return top - 2 * h - 0.12


def _graph(fig, diagram: Mapping[str, Any], rect: tuple[float, float, float, float]) -> None:
    """The graph at ``rect`` = (left, bottom, width, height), inches."""
    from matplotlib.ticker import FuncFormatter

    w, h = fig.get_size_inches()
    left, bottom, width, height = rect
    ax = fig.add_axes((left / w, bottom / h, width / w, height / h), label=f"diagram:{diagram['name']}")
    name, unit = subscripted(diagram["name"]), unit_text(diagram["unit"])
    colour = "#1f5fa8"
    if diagram["kind"] == "cycle":
        xs, ys = diagram["positions"], diagram["values"]
        ax.plot(xs, ys, color=colour, lw=1.4, marker="o", ms=3)
        ax.fill_between(xs, ys, 0, color=colour, alpha=0.12, lw=0)
        ax.set_xlabel("table position", fontsize=8)
        ax.set_xlim(xs[0] - 0.3, xs[-1] + 0.3)
    else:
        for k, stroke in enumerate(diagram["strokes"]):
            xs = [k + t for t in stroke["fractions"]]
            ax.plot(xs, stroke["values"], color=colour, lw=1.4, marker="o", ms=3)
            ax.fill_between(xs, stroke["values"], 0, color=colour, alpha=0.12, lw=0)
        for zone in diagram["strokes"][0]["zones"][1:]:
            ax.axvline(zone["from"], color="0.5", lw=0.6, ls=":")
        two = len(diagram["strokes"]) > 1
        ax.set_xlim(-0.03, 2.03 if two else 1.03)
        if two:
            ax.axvline(1.0, color="0.2", lw=0.8)
            ax.set_xticks([0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75, 2])
            ax.set_xticklabels(["0", "", "0.5", "", "1 | 0", "", "0.5", "", "1"])
            ax.set_xlabel("t: working stroke | idle stroke", fontsize=8)
        else:
            ax.set_xticks([0, 0.25, 0.5, 0.75, 1])
            ax.set_xticklabels(["0", "0.25", "0.5", "0.75", "1"])
            ax.set_xlabel("t, fraction of the working stroke", fontsize=8)
    ax.axhline(0.0, color="0.3", lw=0.6)
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: number_text(float(v), 6)))
    ax.set_ylabel(f"{name}, {unit}", fontsize=8)
    ax.tick_params(labelsize=7.5)
    ax.grid(True, lw=0.4, color="0.88")
