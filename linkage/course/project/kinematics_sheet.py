"""The kinematics sheet of a course project (sheet 1 of 3), composed on the drawing model.

:func:`kinematics_sheet` lays out, on an A1 landscape sheet (A2 and A3 scaled down):

- top left, the structural diagram (a sketch without scale: links numbered, pairs lettered), the
  structural formula (``I(0,1) → II-RRP(2,3)``), the mobility and each Assur group with its
  class and order;
- under it, the mechanism in its n table positions superimposed at a standard scale μ_l (the
  table positions of ``linkage analyze``: position 1 at the scheme's start, numbered 1..n at
  the output point), the chosen position thick, the output's extreme positions dashed, the
  trajectories of the output point and of the points the report's films trace;
- right of it, the plans of velocities and accelerations at the chosen position
  (:func:`linkage.kinetostatics.plans.build_plans`, the vectors of ``linkage plans``) at the μ_v
  and μ_a ``linkage plans`` draws them at (the longest vector 60–120 mm), coarser only where
  the box is too small, with a note;
- along the bottom, the diagrams of the output and its analogs over ψ, the angle turned from
  position 1 in the direction of rotation (per m of the input's slide for a slide input),
  d/dψ as in the tables (docs/conventions.md);
- on the right above the title block, the scales table and a table comparing the values read
  from the plans (a vector measured to 0.1 mm times its scale; a link's ω and ε from a relative
  vector over the link's length measured at μ_l) with the analytic ones, difference in %.

A scheme driven by a slide gets the sheet without plans (the plans start from a crank's
angular velocity, :func:`~linkage.kinetostatics.plans.require_crank_input`), with a note in
their place saying so.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from ...kinematics.motion import analyze
from ...model.mechanism import Mechanism, Prismatic
from ...report.animation import default_trajectories
from ...report.drawing import Geometry
from ...report.plan_drawings import drawing_scales
from ...report.results import analog_direction
from ...structure import mobility, structure_of
from .frame import WIDTH_MARGIN, TitleInfo, blank_sheet, scales_table, table
from .kinematics_data import KinematicsData, kinematics_data
from .kinematics_parts import (
    SUBSCRIPT,
    LabelPlacer,
    Sketch,
    draw_diagram,
    draw_plan,
    draw_scene,
    drawn_vectors,
    fitting_scale,
    leader,
    number_along_path,
    plan_extent,
    scene_points,
    vector_name,
)
from .kinematics_strokes import (
    across,
    crank_arcs,
    retraced,
    stroke_arrows,
    stroke_senses,
)
from .model import Drawing, Line, Scale, Text

__all__ = ["kinematics_sheet", "SHEET_NAME"]

#: the sheet's name in its title block
SHEET_NAME = "Kinematic analysis"
# ----------------------------------------------------------------------------------------------
# the sheet
# ----------------------------------------------------------------------------------------------


def kinematics_sheet(mech: Mechanism, position: int = 1, paper: str = "A1",
                     title: TitleInfo | None = None) -> Drawing:
    """The kinematics sheet of ``mech`` at the table position ``position`` (1-based) on
    ``paper`` (A1, A2 or A3 landscape): see the module docstring.

    Returns
    -------
    Drawing
        Regions ``structure``, ``mechanism``, ``velocity plan``, ``acceleration plan`` (or
        ``plans`` with the note of a slide input), ``diagram 1..3``, ``scales``,
        ``comparison``, ``notes`` besides the frame's.

    Raises
    ------
    InputError
        A position outside the table or not assembled; a scheme without an output (its diagrams
        need one: add ``[output]``).
    """
    if mech.output is None:
        raise InputError(f"scheme '{mech.name}' declares no output: the kinematics sheet draws the output's "
                         "diagrams; add [output] quantity = \"B.x\" (a point's coordinate, a link's angle or a "
                         "slide) to the scheme")
    data = kinematics_data(mech, position)
    title = title if title is not None else TitleInfo()
    if not title.scheme:
        title = TitleInfo(title.project, mech.name, title.variant, title.student, title.group)
    drawing, free = blank_sheet(paper, title, SHEET_NAME, 1, 3)
    boxes = _layout(free, paper, data.plans is not None)
    if data.plans is not None:               # the positions wider where that draws them larger
        wider = _layout(free, paper, True, share=0.71)
        if _fit_positions(data, wider["mechanism"], boxes["text"])[0] < _fit_positions(
                data, boxes["mechanism"], boxes["text"])[0]:
            boxes = wider
    h = boxes["text"]
    _structure(drawing, data, boxes["structure"], h)
    mu_l = _positions(drawing, data, boxes["mechanism"], h)
    measured = _plans(drawing, data, boxes, h)
    _diagrams(drawing, data, boxes["diagrams"], h)
    x0, y0, x1, y1 = boxes["tables"]
    box = scales_table(drawing, (x0, y1), height=h)
    bottom = y0
    if measured is not None:                     # the comparison stands on the title block
        bottom = _comparison(drawing, data, measured, mu_l, (x0, y0), x1 - x0, h)[3] + 2 * h
    _notes(drawing, data, (x0, bottom, x1, box[1] - 2 * h), h)
    return drawing


def _layout(free, paper: str, plans: bool, share: float = 0.63) -> dict:
    """The boxes of the sheet's parts (mm) inside the frame's free box: the diagrams along the
    bottom (0.3 of the height) left of the title block, above them the structural diagram over
    the mechanism in its positions on the left and the plans right of them, the tables in the
    column above the title block; the left part takes ``share`` of the width. Without plans the
    positions take the plans' width too and
    the note on the plans sits beside the structural diagram."""
    fx0, fy0, fx1, fy1 = free
    height = fy1 - fy0
    g = 6.0 if paper in ("A1", "A2") else 4.0
    right = fx1 - 185.0
    diagrams_top = fy0 + 0.30 * height
    x0, x1 = fx0 + g, right - g
    upper0, upper1 = diagrams_top + g, fy1 - g
    struct_y = upper1 - (0.30 if plans else 0.22) * (upper1 - upper0)
    split = x0 + share * (x1 - x0)
    boxes = {"text": 3.5 if paper == "A1" else 2.5,
             "structure": (x0, struct_y, split - g / 2, upper1),
             "diagrams": (x0, fy0 + g, x1, diagrams_top),
             "tables": (right + 1.0, fy0 + 55.0 + g, fx1 - 1.0, upper1)}
    if plans:
        middle = (upper0 + upper1) / 2
        boxes["mechanism"] = (x0, upper0, split - g / 2, struct_y - g)
        boxes["velocity plan"] = (split + g / 2, middle + g / 2, x1, upper1)
        boxes["acceleration plan"] = (split + g / 2, upper0, x1, middle - g / 2)
    else:
        boxes["mechanism"] = (x0, upper0, x1, struct_y - g)
        boxes["plans"] = (split + g / 2, struct_y, x1, upper1)
    return boxes


def _heading(drawing: Drawing, box, text: str, h: float) -> float:
    """A part's heading at the top left of its box, 1.3 h high or less to fit the box's width;
    returns the y under it (mm)."""
    big = heading_height(h)
    height = min(big, (box[2] - box[0] - 2.0) / (0.7 * WIDTH_MARGIN * max(len(text), 1)))
    if text:
        drawing.add(Text((box[0] + 1.0, box[3] - 1.0), text, height=height, anchor=("left", "top")))
    return box[3] - 1.0 - big - 3.0


def heading_height(h: float) -> float:
    """A heading's text height (mm) on a sheet whose text is ``h`` mm: 5 on A1, 3.5 on the smaller papers."""
    return 5.0 if h >= 3.5 else 3.5


# the structural diagram ---------------------------------------------------------------------


def _structure(drawing: Drawing, data: KinematicsData, box, h: float) -> None:
    drawing.region("structure", box)
    mech, motion = data.mech, data.motion
    top = _heading(drawing, box, "Structural diagram (not to scale) and structural analysis", h)
    x0, y0, x1, _ = box
    sketch_w = 0.45 * (x1 - x0)
    sketch_box = (x0 + 2.0, y0 + 2.0, x0 + sketch_w, top)
    geometry = Geometry(motion, [data.index], [])
    probe = geometry.scene(data.index)
    pts = scene_points(probe, geometry.unit)
    span = np.ptp(pts, axis=0)
    room = (sketch_box[2] - sketch_box[0] - 6 * h, sketch_box[3] - sketch_box[1] - 6 * h)
    factor = min(room[0] / max(span[0], 1e-9), room[1] / max(span[1], 1e-9))
    unit_mm = 4.5 if h >= 3.5 else 3.0
    geometry.unit = unit_mm / factor
    scene = geometry.scene(data.index)
    pts = scene_points(scene, geometry.unit)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    factor = min(room[0] / max(hi[0] - lo[0], 1e-9), room[1] / max(hi[1] - lo[1], 1e-9))
    centre = (lo + hi) / 2
    sketch = Sketch(((sketch_box[0] + sketch_box[2]) / 2, (sketch_box[1] + sketch_box[3]) / 2), tuple(centre), factor)
    pins = draw_scene(drawing, scene, sketch, geometry.unit, layer="links", width=0.6, pin_mm=1.5)
    placer = LabelPlacer(drawing, sketch_box)
    placer.avoid_lines()
    middle = np.array(sketch.origin)
    for name, xy in pins:
        placer.avoid((xy[0] - 2.0, xy[1] - 2.0, xy[0] + 2.0, xy[1] + 2.0))
    for name, xy in pins:
        placer.place(xy, name, h, prefer=np.asarray(xy) - middle, rings=(1.0, 1.6, 2.5, 4.0, 6.0))
    for pair in mech.pairs.values():          # prismatic pairs lettered at their blocks
        if isinstance(pair, Prismatic):
            slider = pair.links[1]
            for link, centre_m, _, _ in scene.blocks:
                if link == slider:
                    xy = sketch.paper(centre_m)
                    placer.place(xy, pair.name, h, rings=(2.5, 3.5, 5.0, 7.0, 9.5), prefer=np.asarray(xy) - middle)
                    break
    for link, poly in scene.bodies:           # link numbers beside their middles
        mid = sketch.paper(np.mean(poly, axis=0))
        placer.place(mid, link, 1.15 * h, rings=(0.8, 1.4, 2.2, 3.2, 4.5))
    for link, centre_m, _, _ in scene.blocks:
        if not any(b[0] == link for b in scene.bodies):
            placer.place(sketch.paper(centre_m), link, 1.15 * h, rings=(2.2, 3.0, 4.0, 5.5))
    # the structural analysis, as a student writes it
    structure = structure_of(mech)
    n, p = len(mech.moving_links), len(mech.pairs)
    lines = [f"Structural formula: {structure.formula}",
             f"Mobility (Chebyshev): W = 3n − 2p₅ − p₄ = 3·{n} − 2·{p} − 0 = {mobility(mech)}",
             f"n = {n} moving links, p₅ = {p} lower pairs (R and P), p₄ = 0", ""]
    for name, joint in structure.input_joints.items():
        lines.append(f"Input: {_input_words(mech, name, joint)} — a mechanism of class I")
    for k, group in enumerate(structure.groups, 1):
        inside = set(group.links)
        outer = [j.name for j in group.joints if not ({j.a, j.b} <= inside)]
        lines.append(f"Group {k}: {group!r} — class {group.group_class}, order {len(outer)}; "
                     f"links {', '.join(group.links)}; pairs {', '.join(j.name for j in group.joints)}; "
                     f"outer pairs {', '.join(outer)}")
    lines.append(f"The mechanism is of class {max((g.group_class for g in structure.groups), key=_roman, default='I')}"
                 " (its highest group's class).")
    _paragraph(drawing, (x0 + sketch_w + 4.0, y0 + 2.0, x1 - 2.0, top), lines, h)


def _roman(text: str) -> int:
    return {"I": 1, "II": 2, "III": 3, "IV": 4}.get(text, 0)


def _input_words(mech: Mechanism, name: str, joint) -> str:
    if mech.coordinate.is_angle:
        return f"crank {name} with the frame {mech.frame}, pair {joint.name} (I({mech.frame},{name}))"
    return f"the driven slide of pair {joint.name} (I({joint.name}))"


def _paragraph(drawing: Drawing, box, lines: list[str], h: float) -> float:
    """Lines of text from the top left of ``box``, each broken at spaces to its width, at the
    height ``h`` or the largest smaller one (down to 1.8 mm) at which they fit the box; returns
    the y under the last (mm). Raises ValueError when they do not fit even so."""
    x0, y0, x1, y1 = box
    for height in (h, 0.9 * h, 0.8 * h, 0.7 * h, 0.6 * h, 1.8):
        rows = _broken(lines, max(int((x1 - x0) / (0.7 * height)), 10))
        if y1 - 1.6 * height * len(rows) >= y0 - 1e-6 or height <= 1.8:
            break
    if y1 - 1.6 * height * len(rows) < y0 - 1e-6:
        raise ValueError(f"the text {lines[0][:40]!r}... does not fit its box of {y1 - y0:.0f} mm")
    y = y1
    for row in rows:
        if row:
            drawing.add(Text((x0, y), row, height=height, anchor=("left", "top")))
        y -= 1.6 * height
    return y


def _broken(lines: list[str], chars: int) -> list[str]:
    """The lines broken at spaces into rows of at most ``chars`` characters (continued rows
    indented)."""
    out = []
    for line in lines:
        rows = [""]
        for w in line.split(" "):
            if rows[-1] and len(rows[-1]) + 1 + len(w) > chars:
                rows.append("   " + w)
            else:
                rows[-1] = f"{rows[-1]} {w}".strip() if rows[-1] else w
        out += rows
    return out


# the mechanism in its positions ------------------------------------------------------------


def _label_point(mech: Mechanism) -> str:
    """Where the positions are numbered: the output point, else the output link's point
    farthest from the frame, else a point the films trace."""
    if mech.output_point is not None:
        return mech.output_point
    quantity = mech.output.quantity
    obj = quantity.rsplit(".", 1)[0]
    if obj in mech.links and mech.links[obj].points:
        frame_points = [np.asarray(p) for p in mech.links[mech.frame].points.values()] or [np.zeros(2)]
        pts = mech.links[obj].points
        # the point of the link whose name is no frame point's, farthest from its own origin
        names = [q for q in pts if q not in mech.links[mech.frame].points] or list(pts)
        return max(names, key=lambda q: math.hypot(*np.asarray(pts[q])) + 0 * len(frame_points))
    if obj in mech.pairs:
        return mech.pairs[obj].point
    return (default_trajectories(mech) or mech.point_names)[-1]


def _positions(drawing: Drawing, data: KinematicsData, box, h: float) -> float:
    """The mechanism at the table positions, superimposed, at the largest standard μ_l whose
    drawing fits ``box``, its strokes marked; returns μ_l (m/mm)."""
    drawing.region("mechanism", box)
    mech, motion = data.mech, data.motion
    label_point = _label_point(mech)
    traced = list(dict.fromkeys([label_point] + default_trajectories(mech)))
    extreme_motion = data.sweep
    x0, y0, x1, top = _positions_room(box, h)
    legend_h = 3 * 1.6 * h + 2.0
    mu, geometry, scenes, lo, hi = _fit_positions(data, box, h)
    scale = Scale("μ_l", mu, "m/mm")
    _heading(drawing, box, f"The mechanism in its {len(data.rows)} table positions, μ_l = {mu:g} m/mm; "
                           f"position {data.index + 1} thick", h)
    centre = (lo + hi) / 2
    origin = ((x0 + x1) / 2, (y0 + legend_h + top) / 2)
    view = drawing.view(scale, origin=origin, at=tuple(centre))
    for k in data.rows:
        if k != data.index:
            draw_scene(drawing, scenes[k], view, geometry.unit, layer="positions", width=0.18, frame=False,
                       pin_mm=0.6)
    for key, row in data.extremes.items():       # the extreme positions, dashed
        geo = Geometry(extreme_motion, [row], [])
        geo.unit = geometry.unit
        sc = geo.scene(row)
        for _, poly in sc.bodies:
            drawing.add(_dashed(view.papers(poly), closed=len(poly) >= 3))
    chosen = scenes.get(data.index) or geometry.scene(data.index)
    draw_scene(drawing, chosen, view, geometry.unit, layer="links", width=0.7, pin_mm=1.0)
    for name, _, curve in chosen.trajectories:
        ok = np.all(np.isfinite(curve), axis=1)
        if ok.sum() >= 2:
            view.line(curve[ok], layer="trajectories", width=0.25, dashed=True)
    placer = LabelPlacer(drawing, (x0, y0 + legend_h, x1, top))
    placer.avoid_lines()
    strokes = stroke_senses(data)
    p_label = {k: view.paper(motion.point(label_point)[k]) for k in data.rows}
    for xy in p_label.values():
        placer.avoid((xy[0] - 0.8, xy[1] - 0.8, xy[0] + 0.8, xy[1] + 0.8))
    for name, xy in [(n, view.paper(p)) for n, p in chosen.points.items()]:   # the chosen position's points
        placer.place(xy, name, 0.9 * h, rings=(0.8, 1.5, 2.4))
    sweep_path = np.array([view.paper(p) for p in extreme_motion.point(label_point)
                           if np.all(np.isfinite(p))])
    to_and_fro = strokes is not None and retraced(sweep_path)
    if to_and_fro:
        normal = across(sweep_path)
        numbers = {str(k + 1): p_label[k] for k in data.rows}
        sides = {str(k + 1): (1 if strokes["leaving"][k] == strokes["working"] else -1) for k in data.rows}
        edges = number_along_path(drawing, placer, numbers, sides, h, normal)
        stroke_arrows(drawing, data, view, label_point, strokes, normal, edges, placer, h)
    else:
        path = np.array(list(p_label.values()))
        middle = path.mean(axis=0) if len(path) else np.zeros(2)
        for k, xy in p_label.items():
            t = placer.place(xy, str(k + 1), h, prefer=np.asarray(xy) - middle, rings=(0.8, 1.6, 2.6, 4.0, 6.0, 8.5))
            if t is not None:
                leader(drawing, xy, t.box())
    for key, row in data.extremes.items():
        xy = view.paper(extreme_motion.point(label_point)[row])
        t = placer.place(xy, f"{label_point}{'′' if key == 'max' else '″'}", h, rings=(1.0, 2.0, 3.5, 5.0, 7.0, 9.0))
        if t is not None:
            leader(drawing, xy, t.box())
    if strokes is not None and mech.coordinate.is_angle and mech.input_range is None:
        crank_arcs(drawing, data, view, strokes, placer, h)
    legend = [f"Numbers 1–{len(data.rows)}: the table positions at point {label_point} (position 1: the "
              f"{_start_words(data)}), in the direction of rotation."]
    if data.extremes:
        legend.append(f"Dashed: the extreme positions of the output {mech.output.quantity} ({label_point}′ max, "
                      f"{label_point}″ min); thin dashed: trajectories of {', '.join(traced)}.")
    if strokes is not None:
        side = " (numbers on the working stroke's side of the path, the idle stroke's opposite)" if to_and_fro else ""
        sense = "increasing" if strokes["working"] > 0 else "decreasing"
        legend.append(f"Working stroke: {mech.output.quantity} {sense}"
                      f", {strokes['why']}{side}.")
    _paragraph(drawing, (x0 + 1.0, y0, x1, y0 + legend_h), legend, h)
    return mu


def _positions_room(box, h: float) -> tuple[float, float, float, float]:
    """The part of the positions' box (mm) under its heading."""
    return (box[0], box[1], box[2], box[3] - 1.0 - heading_height(h) - 3.0)


def _fit_positions(data: KinematicsData, box, h: float):
    """The largest standard μ_l (m/mm) at which the positions (with their symbols, guides and
    trajectories) fit ``box`` less the heading, the legend and a margin for the labels; returns
    μ_l, the geometry, the scenes of the rows and the drawing's extent (lo, hi; m)."""
    x0, y0, x1, top = _positions_room(box, h)
    room = (x1 - x0 - 2 * 4 * h, top - y0 - (3 * 1.6 * h + 2.0) - 2 * 3 * h)
    traced = list(dict.fromkeys([_label_point(data.mech)] + default_trajectories(data.mech)))
    geometry = Geometry(data.motion, data.rows, traced)
    mu = fitting_scale(geometry.span, min(room))
    seen = []
    for _ in range(8):
        geometry.unit = (3.0 if h >= 3.5 else 2.2) * mu
        scenes = {k: geometry.scene(k) for k in data.rows}
        pts = np.vstack([scene_points(s, geometry.unit) for s in scenes.values()])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        fits = max(fitting_scale(hi[0] - lo[0], room[0]), fitting_scale(hi[1] - lo[1], room[1]))
        if fits == mu or fits in seen:
            mu = max(mu, fits)
            if fits != mu:
                continue
            break
        seen.append(mu)
        mu = fits
    geometry.unit = (3.0 if h >= 3.5 else 2.2) * mu
    scenes = {k: geometry.scene(k) for k in data.rows}
    pts = np.vstack([scene_points(s, geometry.unit) for s in scenes.values()])
    return mu, geometry, scenes, pts.min(axis=0), pts.max(axis=0)


def _dashed(points, closed: bool) -> Line:
    return Line(tuple(points), layer="positions", width=0.35, dashed=True, closed=closed)


def _start_words(data: KinematicsData) -> str:
    start = data.results.meta["start"]
    if start == "extreme":
        return f"extreme position, {data.mech.output.start} of {data.mech.output.quantity}"
    if start == "range":
        return "first end of the declared range"
    return f"input angle {float(start):g}°"


# the plans ---------------------------------------------------------------------------------


def _plans(drawing: Drawing, data: KinematicsData, boxes: dict, h: float) -> dict | None:
    """Both plans at the chosen position; returns the plan -> scale drawn (None without plans)."""
    if data.plans is None:
        box = boxes["plans"]
        drawing.region("plans", box)
        _heading(drawing, box, "Plans of velocities and accelerations", h)
        _paragraph(drawing, (box[0] + 1.0, box[1], box[2] - 1.0, box[3] - heading_height(h) - 5.0),
                   [f"Not drawn: scheme '{data.mech.name}' is driven by a slide ({data.mech.inputs[0]}, m). "
                    "The plans start from a crank's angular velocity (rad/s); for a slide input see the diagrams "
                    "of the analogs per m of the slide below and `linkage analyze`."], h)
        return None
    scales = {}
    students_scales = drawing_scales(data.plans, 0)
    for quantity, symbol, unit, pole in (("velocity", "μ_v", "(m/s)/mm", "p"),
                                         ("acceleration", "μ_a", "(m/s²)/mm", "π")):
        box = boxes[f"{quantity} plan"]
        drawing.region(f"{quantity} plan", box)
        plan = getattr(data.plans, quantity)
        lo, hi, _ = plan_extent(plan, 0)
        x0, y0, x1, y1 = box
        room = (x1 - x0 - 8 * h, y1 - y0 - heading_height(h) - 8 * h)
        shared = students_scales[quantity]
        mu = max(shared, fitting_scale(hi[0] - lo[0], room[0]), fitting_scale(hi[1] - lo[1], room[1]))
        if mu != shared:
            data.notes.append(f"the {quantity} plan is drawn at {symbol} = {mu:g} {unit}, coarser than the "
                              f"{shared:g} of `linkage plans` (its longest vector 60-120 mm), to fit the sheet")
        scale = Scale(symbol, mu, unit)
        plural = "velocities" if quantity == "velocity" else "accelerations"
        _heading(drawing, box, f"Plan of {plural}, position {data.index + 1}: {scale}", h)
        top = y1 - heading_height(h) - 3.0
        view = drawing.view(scale, origin=((x0 + x1) / 2, (y0 + top) / 2), at=tuple((lo + hi) / 2))
        draw_plan(drawing, plan, 0, view, pole, h, (x0, y0, x1, top))
        scales[quantity] = mu
    return scales


def _comparison(drawing: Drawing, data: KinematicsData, scales: dict, mu_l: float, bottom_left, width: float,
                h: float):
    """The table of values by the plans against the analytic ones, its heading over it, standing
    on ``bottom_left`` (mm); its cells at the largest of 3.5, 3 and 2.5 mm its columns fit in
    ``width``. Returns the box of the table and its heading."""
    plans, mech = data.plans, data.mech
    motion = analyze(mech, data.motion.phi[data.index:data.index + 1], order=2, omega=data.omega, eps=0.0)
    rows = []

    def row(name, length_mm, mu, analytic, unit, by_plan=None):
        by_plan = round(length_mm, 1) * mu if by_plan is None else by_plan
        if abs(analytic) < 1e-9 * max(mu, 1e-300) * 1e3 or round(length_mm, 1) == 0:
            rows.append([name, f"{length_mm:.1f}", f"{by_plan:.4g}", "0", unit, "—"])
            return
        diff = (by_plan - analytic) / analytic * 100
        rows.append([name, f"{length_mm:.1f}", f"{by_plan:.4g}", f"{analytic:.4g}", unit,
                     f"{diff:+.2f}".replace("-0.00", "0.00").replace("+0.00", "0.00")])

    named = set(mech.point_names)
    for quantity, unit in (("velocity", "m/s"), ("acceleration", "m/s²")):
        plan, mu = getattr(plans, quantity), scales[quantity]
        get = motion.velocity if quantity == "velocity" else motion.acceleration
        for v in drawn_vectors(plan):
            if v.kind == "absolute" and v.point in named:
                length = float(np.hypot(*v.vector[0])) / mu
                row(vector_name(v, quantity), length, mu, float(np.hypot(*get(v.point)[0])), unit)
        kind, symbol, unit_k = (("relative", "ω", "rad/s") if quantity == "velocity" else
                                ("tangential", "ε", "rad/s²"))
        for link in mech.moving_links:
            if link in mech.inputs:
                continue
            vec = next((v for v in drawn_vectors(plan) if v.kind == kind and v.link == link
                        and v.point in named and v.about in named), None)
            if vec is None:
                continue
            arm_mm = float(np.hypot(*(motion.point(vec.point)[0] - motion.point(vec.about)[0]))) / mu_l
            length = float(np.hypot(*vec.vector[0])) / mu
            by_plan = round(length, 1) * mu / (round(arm_mm, 1) * mu_l)
            analytic = float(abs(motion.first[link][0, 2] * data.omega if quantity == "velocity" else
                                 motion.second[link][0, 2] * data.omega ** 2))
            row(f"{symbol}{link.translate(SUBSCRIPT)} = {vector_name(vec, quantity)}/l_{vec.point}{vec.about}",
                length, mu, analytic, unit_k, by_plan)
    header = ["quantity", "length\non plan,\nmm", "by the\nplan", "analytic", "unit", "differ-\nence, %"]
    for cell in (3.5, 3.0, 2.5) if h >= 3.5 else (2.5,):
        need = [max(len(line) for text in [head] + [r[c] for r in rows] for line in text.split("\n"))
                * 0.7 * WIDTH_MARGIN * cell + 2.0 for c, head in enumerate(header)]
        if sum(need) <= width:
            break
    widths = [w + (width - sum(need)) * w / sum(need) for w in need]
    row_h = 2 * cell + 1
    tall = row_h + 1.6 * cell * 2 + row_h * len(rows)
    x0, y0 = bottom_left
    title = f"Plans against the analytic values, position {data.index + 1}"
    heading = min(h, (width - 1.0) / (0.7 * WIDTH_MARGIN * len(title)))
    drawing.add(Text((x0, y0 + tall + 1.0), title, height=heading, anchor=("left", "bottom")))
    box = table(drawing, (x0, y0 + tall), header, rows, widths, height=cell, name="comparison")
    return (box[0], box[1], box[2], box[3] + 1.0 + heading)


def _notes(drawing: Drawing, data: KinematicsData, box, h: float) -> None:
    lines = [f"Analogs per rad turned from position 1 in the direction of rotation (ψ), docs/conventions.md."
             if data.mech.coordinate.is_angle else "Analogs per m of the input's slide s."]
    if data.plans is not None:
        lines.append(f"Plans at ω₁ = {data.omega:g} rad/s, ε₁ = 0; a vector's value = its length on the plan "
                     "(to 0.1 mm) × its scale; ω, ε of a link = a relative vector over the link's length at μ_l.")
    lines += [n[0].upper() + n[1:] for n in data.notes]
    if box[3] - box[1] < 3 * h:
        return
    drawing.region("notes", box)
    _paragraph(drawing, box, lines, h)


# the diagrams ------------------------------------------------------------------------------


def _diagrams(drawing: Drawing, data: KinematicsData, box, h: float) -> None:
    mech, sweep = data.mech, data.sweep
    quantity = mech.output.quantity
    value, d1, d2 = sweep.quantity(quantity)
    d1 = d1 * analog_direction(mech, sweep.phi)
    s = value - value[0]
    angle_out = quantity.endswith(".theta")
    is_angle = mech.coordinate.is_angle
    x = data.psi
    x_span = float(np.nanmax(x) - np.nanmin(x))
    x0, y0, x1, y1 = box
    gap = 8.0
    width = (x1 - x0 - 2 * gap) / 3
    small = 2.5
    left = 3.5 * small + 4.0                      # the y axis's numbers left of it, mm
    x_room = width - left - 6.0 - 1.0 - 0.7 * WIDTH_MARGIN * h * 7
    if is_angle:
        x_scale = Scale("μ_φ", fitting_scale(x_span, x_room), "rad/mm")
        x_label, per = "ψ, rad", "rad"
    else:
        x_scale = Scale("μ_q", fitting_scale(x_span, x_room), "m/mm")
        x_label, per = "s_in, m", "m"
    out_unit = "rad" if angle_out else "m"
    sym = "θ" if angle_out else "s"
    link_or_point = quantity.split(".")[0].translate(SUBSCRIPT)
    base = f"{sym}{link_or_point}" if angle_out else f"s_{link_or_point}"
    d = "dψ" if is_angle else "ds_in"
    curves = [(s, f"μ_{sym}", f"{out_unit}/mm", f"{base} = {quantity} − ({quantity})₁, {out_unit}",
               f"Output {quantity}: displacement {base}(ψ)" if is_angle else f"Output {quantity}: {base}(s_in)"),
              (d1, f"μ_{sym}′", _per(out_unit, per, 1), f"d{base}/{d}, {_unit(out_unit, per, 1)}",
               f"First analog d{base}/{d}"),
              (d2, f"μ_{sym}″", _per(out_unit, per, 2), f"d²{base}/{d}², {_unit(out_unit, per, 2)}",
               f"Second analog d²{base}/{d}²")]
    ticks = []
    table_x = np.abs(data.motion.phi - data.motion.phi[0]) if is_angle else data.motion.phi
    for k, xt in enumerate(table_x):
        ticks.append((float(xt), str(k + 1)))
    for n, (y, symbol, unit, y_label, title) in enumerate(curves):
        bx0 = x0 + n * (width + gap)
        bbox = (bx0, y0, bx0 + width, y1)
        drawing.region(f"diagram {n + 1}", bbox)
        ok = np.isfinite(y)
        lo, hi = min(float(np.min(y[ok])), 0.0), max(float(np.max(y[ok])), 0.0)
        text_h = 3 * 1.6 * h + 1.5 + 6.0          # the title, scales and axis name over the axis's arrow
        y_room = (y1 - y0) - text_h - (small + 4.0) - 2.0
        y_scale = Scale(symbol, fitting_scale(hi - lo if hi > lo else 1.0, y_room), unit)
        xs0 = float(np.nanmin(x))
        origin = (bx0 + left, y0 + small + 4.0 + (0.0 - lo) / y_scale.value)
        view = drawing.view(x_scale, origin=origin, at=(xs0, 0.0), scale_y=y_scale)
        draw_diagram(drawing, view, x, y, x_label=x_label, y_label=y_label,
                     title=f"{title}\n{x_scale}, {y_scale}", height=h, ticks=ticks, width=width - 2.0,
                     small=small)


def _per(out_unit: str, per: str, order: int) -> str:
    if out_unit == per:
        return "1/mm" if order == 1 else f"(1/{per})/mm"
    return f"({out_unit}/{per}{'²' if order == 2 else ''})/mm"


def _unit(out_unit: str, per: str, order: int) -> str:
    if out_unit == per:
        return "1" if order == 1 else f"1/{per}"
    return f"{out_unit}/{per}{'²' if order == 2 else ''}"

