"""The kinetostatics sheet of a course project: each Assur group drawn apart with its loads and
reactions, the force polygons, Zhukovsky's lever and the check of the balancing moment.

At one table position the sheet shows, row by row (the groups in the order they are solved, from
the farthest, then the input links): the group drawn apart at the sheet's ``μ_l`` with its applied
forces, gravity, inertia forces, inertia and applied moments (curved arrows with their values) and
the reactions of its outer pairs; its force polygon at the sheet's one ``μ_F``; and a table of
every polygon vector's length and value. An outer revolute pair of a dyad whose link meets the
other link in a revolute pair has its reaction split as the course does (METHOD §10):
``R = Rⁿ + Rτ``, ``Rτ`` across the link from the link's moment equation about the inner pair,
``Rⁿ`` along the link from the group's polygon, which is drawn in the student's order (``Rτ``
first, the loads, ``Rⁿ`` closing it) with the whole reactions as resultants. On the right:
Zhukovsky's lever (the velocity plan turned 90° clockwise at ``μ_v``, the forces at the images
of their points), its table of moments, a table comparing ``M_b`` by the polygons and by the
lever, the scales and the notes.

Every number comes from :func:`linkage.kinetostatics.plans.build_plans` (the plans, polygons and
lever of ``linkage plans``) at the positions of ``linkage forces``; the split is the only thing
computed here. Arrows on the groups and on the lever give the lines and senses of the forces (not
to scale); the polygons are to scale.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...kinematics.motion import table_positions_deg
from ...kinetostatics.plans import POLE, ForcePolygon, Plans, PolygonForce, build_plans, require_crank_input
from ...model.mechanism import Prismatic, Revolute
from ...model.scheme import section_of
from ...report.drawing import Geometry
from ...report.plan_drawings import nice_scale
from ...report.results import forces_results
from .frame import TitleInfo, blank_sheet, scales_table, table
from .model import Arrow, Circle, Drawing, Line, Scale, Text, standard_scale

__all__ = ["DrawnVector", "ReactionSplit", "KinetostaticsSheet", "compose_kinetostatics", "kinetostatics_sheet",
           "split_reactions"]

#: text heights: headings, labels, tables, mm
HEADING, LABEL, SMALL = 5.0, 3.5, 2.5
#: a polygon vector shorter than this carries no label on the drawing (its table names it), mm
LABELLED_MM = 4.0
#: a force arrow on a group or on the lever: the shortest and longest, mm (not to scale)
ARROW_MM = (9.0, 24.0)
#: a polygon whose longest vector is shorter than this at the sheet's μ_F is called tiny in a note, mm
TINY_MM = 20.0
#: the room kept around a group for its arrows and labels, mm
GROUP_MARGIN = 34.0


@dataclass(frozen=True)
class DrawnVector:
    """A vector of a force polygon as drawn from ``start`` to ``end`` (mm; ``items``: its arrow, or
    a dashed line and a head) standing for ``value`` ``(2,)``, N.

    ``kind``: ``force`` (a force of :class:`~linkage.kinetostatics.plans.ForcePolygon`, ``label``
    its label), ``internal`` (the reaction between the group's links), ``normal`` / ``tangential``
    (the parts ``Rⁿ``, ``Rτ`` of a split reaction ``label``) or ``resultant`` (the whole split
    reaction ``label`` drawn as their sum)."""

    step: str
    label: str
    kind: str
    start: tuple[float, float]
    end: tuple[float, float]
    value: np.ndarray
    items: tuple = ()

    @property
    def length(self) -> float:
        """The drawn length, mm."""
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])


@dataclass(frozen=True)
class ReactionSplit:
    """The reaction ``whole`` ``(2,)``, N, of an outer revolute ``pair`` (at ``point``, m) on
    ``link`` of a dyad, as ``normal`` (along ``point`` -> ``inner_point``, the link's revolute
    pair with the other link of the group) plus ``tangential`` (across), N."""

    step: str
    label: str
    pair: str
    link: str
    inner_pair: str
    point: np.ndarray
    inner_point: np.ndarray
    whole: np.ndarray
    normal: np.ndarray
    tangential: np.ndarray


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
        ``"A1"`` (the layout is made for it), ``"A2"``, ``"A3"``.
    title : TitleInfo
        The title block's names (the scheme's name when ``title.scheme`` is empty).
    omega : float, optional
        The input's angular velocity, rad/s (signed); default ``[dynamics] mean_speed``.

    Raises
    ------
    InputError
        A slide input; no ``[loads]``; no speed; a position outside the table or not assembled.
    """
    plans, i, notes = _analysis(mech, position, omega)
    if not title.scheme:
        title = dataclasses.replace(title, scheme=mech.name)
    drawing, free = blank_sheet(paper, title, "Kinetostatic analysis", 2, 3)
    sheet = KinetostaticsSheet(drawing, plans, i, 0.0, 0.0, 0.0, notes=notes)
    _Composer(sheet, free).compose()
    return sheet


# ----------------------------------------------------------------------------------------------
# the numbers
# ----------------------------------------------------------------------------------------------


def _analysis(mech, position: int, omega: float | None) -> tuple[Plans, int, list[str]]:
    require_crank_input(mech)
    if mech.extra.get("loads") is None:
        raise InputError(f"scheme '{mech.name}' declares no [loads]: add [loads] (gravity = [0, -9.81] and the "
                         "forces, [[loads.forces]]) to draw its kinetostatics sheet")
    if omega is None:
        spec = section_of(mech, "dynamics")
        omega = None if spec is None else spec.mean_speed
    if omega is None:
        raise InputError(f"scheme '{mech.name}' declares no speed: add [dynamics] mean_speed = W (rad/s, signed) "
                         "or give omega to draw its kinetostatics sheet (the inertia forces and the lever need it)")
    if not (math.isfinite(omega) and omega != 0):
        raise InputError(f"omega {omega!r}: the kinetostatics sheet needs a moving input, a nonzero finite rad/s")
    results = forces_results(mech, omega=omega)
    count = len(results.motion.phi)
    if not 1 <= position <= count:
        raise InputError(f"position {position}: scheme '{mech.name}' has the table positions 1 to {count}")
    failed = [f for f in results.meta["failed"] if f["position"] == position]
    if failed:
        raise InputError(f"position {position}: scheme '{mech.name}' {failed[0]['problem']} at the input angle "
                         f"{failed[0]['input_angle_deg']:.6g} deg: it has no kinetostatics there")
    return build_plans(results.motion, results.reactions), position - 1, list(results.notes)


def _global(motion, link: str, local, i: int) -> np.ndarray:
    """Global position ``(2,)``, m, of the point ``local`` of ``link`` at position ``i``."""
    if link == motion.mechanism.frame:
        return np.asarray(local, float)
    return motion.poses[link][i, :2] + motion.arm(link, np.asarray(local, float))[i]


def _pair_point(motion, pair: str, link: str, i: int) -> np.ndarray:
    """Where the pair ``pair`` acts on ``link``, m (a prismatic pair: at its slider's point)."""
    mech = motion.mechanism
    p = mech.pairs[pair]
    owner = link if p.point in mech.links[link].points else next(k for k in p.links if p.point in mech.links[k].points)
    return _global(motion, owner, mech.links[owner].points[p.point], i)


def _force_point(plans: Plans, f: PolygonForce, i: int) -> np.ndarray:
    """Where the polygon force ``f`` acts, m."""
    motion = plans.motion
    if f.kind == "reaction":
        return _pair_point(motion, f.pair, f.link, i)
    for t in plans.reactions.terms:
        if t.link == f.link and t.label == f.label:
            return _global(motion, t.link, t.local, i)
    raise KeyError(f"no load {f.label} on link {f.link}")


def _inner_revolute(mech, polygon: ForcePolygon) -> dict[str, str]:
    """link -> the revolute pair joining it to the other link of a dyad (empty unless the two
    links of the group meet in exactly one pair and it is revolute)."""
    if len(polygon.links) != 2:
        return {}
    inner = [n for n, p in mech.pairs.items() if set(p.links) == set(polygon.links)]
    if len(inner) != 1 or not isinstance(mech.pairs[inner[0]], Revolute):
        return {}
    return {k: inner[0] for k in polygon.links}


def split_reactions(plans: Plans, polygon: ForcePolygon, i: int) -> list[ReactionSplit]:
    """The splits ``R = Rⁿ + Rτ`` of the reactions a dyad's polygon finds in its outer revolute
    pairs: ``Rτ`` from the moment equation of the reaction's link about the inner pair C (every
    other force and moment on the link), ``Rⁿ`` the projection of the polygon's reaction on BC."""
    mech = plans.motion.mechanism
    inner = _inner_revolute(mech, polygon)
    out = []
    for f in polygon.forces:
        if not (f.kind == "reaction" and f.unknown and f.link in inner and isinstance(mech.pairs[f.pair], Revolute)):
            continue
        b = _pair_point(plans.motion, f.pair, f.link, i)
        c = _pair_point(plans.motion, inner[f.link], f.link, i)
        length = float(np.hypot(*(c - b)))
        if length <= 1e-9 * mech.size:
            continue
        e_n = (c - b) / length
        e_t = np.array([-e_n[1], e_n[0]])
        moment = 0.0                                   # about C, of every other force and moment on the link
        for g in polygon.on_link(f.link):
            if g.label == f.label or g.pair == inner[f.link]:
                continue
            r = _force_point(plans, g, i) - c
            moment += float(r[0] * g.vector[i, 1] - r[1] * g.vector[i, 0])
        moment += sum(float(m.value[i]) for m in polygon.moments if m.link == f.link)
        tangential = (moment / length) * e_t
        normal = float(f.vector[i] @ e_n) * e_n
        out.append(ReactionSplit(polygon.step, f.label, f.pair, f.link, inner[f.link], b, c, f.vector[i].copy(),
                                 normal, tangential))
    return out


# ----------------------------------------------------------------------------------------------
# names and numbers as written on the sheet
# ----------------------------------------------------------------------------------------------

_SUB = str.maketrans("0123456789,", "₀₁₂₃₄₅₆₇₈₉‚")


def name(label: str, part: str = "") -> str:
    """A polygon label as written: ``R[2,1]`` -> R₂₁, ``G2`` -> G₂, ``Fi2`` -> Fᵢ₂, ``Mi2`` ->
    Mᵢ₂; ``part`` ``"n"`` / ``"t"`` gives Rⁿ₂₁ / Rτ₂₁."""
    top = {"n": "ⁿ", "t": "τ", "": ""}[part]
    m = re.fullmatch(r"([RM])\[(.+?),(.+?)\](?:\((.+)\))?", label)
    if m:
        head, a, b, pair = m.groups()
        sub = (a + b) if len(a) == len(b) == 1 else f"{a},{b}"
        return f"{head}{top}{sub.translate(_SUB)}" + (f"({pair})" if pair else "")
    m = re.fullmatch(r"(G|Fi|Mi|Mb)(\d+)", label)
    if m:
        head, link = m.groups()
        return head[0] + {"i": "ᵢ", "b": "b"}.get(head[1:], "") + link.translate(_SUB)
    return label


def _num(x: float) -> str:
    """4 significant digits (whole numbers from 10 000 up), a true minus, no -0."""
    text = f"{x:.0f}" if 1e4 <= abs(x) < 1e9 else f"{x:.4g}"
    return ("0" if float(text) == 0 else text).replace("-", "−")


def _arrow_mm(value: float, largest: float) -> float:
    """The (not to scale) length of a force arrow on a group or the lever, mm."""
    low, high = ARROW_MM
    return low + (high - low) * math.sqrt(value / largest) if largest > 0 else low


# ----------------------------------------------------------------------------------------------
# composing
# ----------------------------------------------------------------------------------------------


class _Labels:
    """Places texts without overlapping the sheet's other texts, inside a box, away from lines."""

    def __init__(self, drawing: Drawing):
        self.drawing = drawing
        self.boxes: list[tuple[float, float, float, float]] = []
        self.marks: list[np.ndarray] = []          # sampled points of the lines drawn

    def taken(self, box) -> None:
        self.boxes.append(tuple(box))

    def mark(self, points) -> None:
        pts = np.asarray(points, float).reshape(-1, 2)
        for a, b in zip(pts[:-1], pts[1:]):
            n = max(int(np.hypot(*(b - a)) / 1.0), 1)
            self.marks.append(a + np.linspace(0, 1, n + 1)[:, None] * (b - a))
        if len(pts) == 1:
            self.marks.append(pts)

    def add(self, at, text: str, within, height: float = LABEL, prefer=(1.0, 1.0), layer: str = "text",
            gap: float = 1.2) -> Text | None:
        """Put ``text`` near ``at`` (mm), inside ``within``; None when no place is free."""
        marks = np.vstack(self.marks) if self.marks else np.zeros((0, 2))
        prefer = np.asarray(prefer, float)
        prefer = prefer / (np.hypot(*prefer) or 1.0)
        best, best_cost = None, math.inf
        for ring in (gap, gap + 2.5, gap + 5.0, gap + 8.0, gap + 12.0):
            for angle in np.radians(np.arange(0, 360, 30)):
                d = np.array([math.cos(angle), math.sin(angle)])
                h = ("left" if d[0] > 0.3 else "right" if d[0] < -0.3 else "center")
                v = ("bottom" if d[1] > 0.3 else "top" if d[1] < -0.3 else "middle")
                item = Text((float(at[0] + ring * d[0]), float(at[1] + ring * d[1])), text, height=height,
                            layer=layer, anchor=(h, v))
                box = item.box()
                if not _inside(box, within) or any(_overlap(box, b) for b in self.boxes):
                    continue
                hits = int(np.sum((marks[:, 0] > box[0]) & (marks[:, 0] < box[2]) & (marks[:, 1] > box[1])
                                  & (marks[:, 1] < box[3]))) if len(marks) else 0
                cost = 10.0 * hits + ring + 2.0 * (1.0 - float(d @ prefer))
                if cost < best_cost:
                    best, best_cost = item, cost
            if best is not None and best_cost < ring + 10.0:
                break
        if best is None:
            return None
        self.boxes.append(best.box())
        return self.drawing.add(best)


def _inside(box, outer) -> bool:
    return box[0] >= outer[0] and box[1] >= outer[1] and box[2] <= outer[2] and box[3] <= outer[3]


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    n = float(np.hypot(*v))
    return v / n if n > 0 else np.array([1.0, 0.0])


class _Composer:
    def __init__(self, sheet: KinetostaticsSheet, free):
        self.sheet = sheet
        self.d = sheet.drawing
        self.plans = sheet.plans
        self.i = sheet.index
        self.mech = self.plans.motion.mechanism
        self.free = free
        self.labels = _Labels(self.d)
        for item in self.d.items:
            if isinstance(item, Text):
                self.labels.taken(item.box())
        order = {p.step: p for p in self.plans.polygons}
        inputs = [p for p in self.plans.polygons if p.step.startswith("I(")]
        groups = [p for p in self.plans.polygons if not p.step.startswith("I(")]
        self.rows = list(reversed(groups)) + inputs            # as solved: the farthest group first
        self.splits = {p.step: split_reactions(self.plans, p, self.i) for p in order.values()}
        sheet.splits = [s for p in self.rows for s in self.splits[p.step]]
        self.scene = Geometry(self.plans.motion, [self.i]).scene(self.i)

    # -- layout --------------------------------------------------------------------------------
    def compose(self) -> None:
        x0, y0, x1, y1 = self.free
        width = x1 - x0
        head_h = 14.0
        self._heading((x0 + 5, y1 - 4))
        right_w = min(280.0, 0.34 * width)
        left = (x0 + 4, y0 + 4, x1 - right_w - 8, y1 - head_h)
        right = (x1 - right_w - 2, y0 + 4, x1 - 4, y1 - head_h)
        n = len(self.rows)
        row_h = (left[3] - left[1]) / n
        lw = left[2] - left[0]
        table_w = 76.0
        cell_w = (lw - table_w - 8) / 2
        rows = []
        for k, polygon in enumerate(self.rows):
            top = left[3] - k * row_h
            rows.append((polygon, (left[0], top - row_h + 3, left[0] + cell_w, top - 1),
                         (left[0] + cell_w + 2, top - row_h + 3, left[0] + 2 * cell_w, top - 1),
                         (left[2] - table_w, top - 1)))
        self._choose_scales(rows)
        for polygon, group_box, polygon_box, table_at in rows:
            self._group(polygon, group_box)
            self._polygon(polygon, polygon_box, table_at)
        self._right(right)

    def _heading(self, at) -> None:
        motion = self.plans.motion
        turned = float(table_positions_deg(motion.phi, motion.direction)[self.i])
        phi = (math.degrees(float(motion.phi[self.i])) + 180.0) % 360.0 - 180.0
        omega = float(motion.omega[self.i])
        text = (f"Kinetostatic analysis of '{self.mech.name}' at position {self.i + 1} of {len(motion.phi) - 1} "
                f"(turned {_num(turned)}° from position 1, input angle {_num(phi)}°, ω₁ = {_num(omega)} rad/s, ε₁ = {_num(float(motion.eps[self.i]))} rad/s²)")
        self.d.add(Text(at, text, height=HEADING, anchor=("left", "top")))
        self.labels.taken(self.d.items[-1].box())

    def _choose_scales(self, rows) -> None:
        i = self.i
        # μ_l: the largest group (or input link) fits its cell with room for the arrows
        need = 0.0
        for polygon, box, _, _ in rows:
            pts = self._link_points(polygon.links)
            span = np.ptp(pts, axis=0)
            room = (box[2] - box[0] - 2 * GROUP_MARGIN, box[3] - box[1] - 2 * GROUP_MARGIN - 8)
            need = max(need, span[0] / room[0], span[1] / room[1])
        self.mu_l = nice_scale(need)
        # μ_F: one for every polygon, the largest polygon's longest vector 60..120 mm, every polygon in its cell
        longest = max(float(np.hypot(*v.vector[i])) for p in self.plans.polygons for v in p.forces)
        mu_f = standard_scale(longest, 60.0, 120.0)
        for polygon, _, box, _ in rows:
            span = np.ptp(self._chain(polygon), axis=0)
            room = (box[2] - box[0] - 24, box[3] - box[1] - 24)
            mu_f = max(mu_f, nice_scale(max(span[0] / room[0], span[1] / room[1])))
        self.mu_f = mu_f
        if longest / mu_f < 60.0:
            self.sheet.notes.append(f"μ_F is chosen so the polygons fit their places: the longest vector is "
                                    f"{longest / mu_f:.0f} mm")
        for polygon in self.plans.polygons:
            top = max(float(np.hypot(*v.vector[i])) for v in polygon.forces)
            if top / mu_f < TINY_MM:
                self.sheet.notes.append(f"the polygon of {polygon.step} is small at μ_F = {_num(mu_f)} N/mm (its "
                                        f"longest vector {top / mu_f:.1f} mm): its table gives the values")
        self.sheet.mu_l, self.sheet.mu_f = self.mu_l, self.mu_f
        self.d.use(Scale("μ_l", self.mu_l, "m/mm"))
        self.d.use(Scale("μ_F", self.mu_f, "N/mm"))

    def _link_points(self, links) -> np.ndarray:
        mech, motion = self.mech, self.plans.motion
        pts = [_global(motion, k, local, self.i) for k in links for local in mech.links[k].points.values()]
        return np.array(pts).reshape(-1, 2)

    # -- a group drawn apart ---------------------------------------------------------------------
    def _group(self, polygon: ForcePolygon, box) -> None:
        d, i = self.d, self.i
        kind = "input link" if polygon.step.startswith("I(") else "group"
        links = ", ".join(polygon.links)
        title = Text((box[0] + 2, box[3] - 1), f"{'Input link' if kind == 'input link' else 'Group'} "
                     f"{polygon.step}: link{'s' if len(polygon.links) > 1 else ''} {links}, μ_l = {_num(self.mu_l)} m/mm",
                     height=LABEL, anchor=("left", "top"))
        d.add(title)
        self.labels.taken(title.box())
        d.region(f"group {polygon.step}", box)
        pts = self._link_points(polygon.links)
        centre_q = (pts.min(axis=0) + pts.max(axis=0)) / 2
        centre_mm = ((box[0] + box[2]) / 2, (box[1] + box[3]) / 2 - 4)
        view = d.view(Scale("μ_l", self.mu_l, "m/mm"), origin=centre_mm, at=tuple(centre_q)).paper
        inside = set(polygon.links)
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
        for link, centre, angle, _ in sc.blocks:
            if link in inside:
                self._block(view(centre), angle)
        for pair in self.mech.pairs.values():
            if isinstance(pair, Revolute) and set(pair.links) & inside:
                p = view(_pair_point(self.plans.motion, pair.name, next(k for k in pair.links if k in inside), i))
                d.add(Circle(p, 1.5, layer="links", width=0.5))
                self.labels.mark([p])
                self.labels.add(p, pair.point, box, height=SMALL, prefer=(-1, 1), gap=2.0)
            elif isinstance(pair, Prismatic) and set(pair.links) & inside and not set(pair.links) <= inside:
                guide_link = pair.links[0]
                if guide_link not in inside:          # the removed guide: its line through the slider
                    centre = _pair_point(self.plans.motion, pair.name, pair.links[1], i)
                    u = self._guide_direction(pair)
                    a, b = view(centre - 14 * self.mu_l * u), view(centre + 14 * self.mu_l * u)
                    d.add(Line((a, b), layer="links", width=0.35, dashed=True))
        # the forces: loads and known reactions as they are, the unknown reactions split or whole
        splits = {s.label: s for s in self.splits[polygon.step]}
        shown: list[tuple[np.ndarray, np.ndarray, str]] = []
        for f in polygon.forces:
            at = _force_point(self.plans, f, i)
            if f.label in splits:
                s = splits[f.label]
                shown.append((at, s.normal, name(f.label, "n")))
                shown.append((at, s.tangential, name(f.label, "t")))
            else:
                shown.append((at, f.vector[i], name(f.label)))
        largest = max([float(np.hypot(*v)) for _, v, _ in shown] + [0.0])
        for at, vector, label in shown:
            size = float(np.hypot(*vector))
            if size <= 1e-9 * largest:
                continue
            start = np.array(view(at))
            end = start + _arrow_mm(size, largest) * _unit(vector)
            d.add(Arrow(tuple(start), tuple(end), layer="forces", width=0.5, head=3.0))
            self.labels.mark([start, end])
            self.labels.add(end, label, box, height=LABEL, prefer=_unit(vector))
        for m in polygon.moments:
            value = float(m.value[i])
            if value == 0 or not np.isfinite(value):
                continue
            at = self._moment_point(m)
            self._curved(np.array(view(at)), value, f"{name(m.label)} = {_num(value)} N·m", box)

    def _moment_point(self, m) -> np.ndarray:
        mech, i = self.mech, self.i
        if m.pair is not None:
            return _pair_point(self.plans.motion, m.pair, m.link, i)
        return _global(self.plans.motion, m.link, mech.links[m.link].center_of_mass, i)

    def _guide_direction(self, pair) -> np.ndarray:
        glink = pair.links[0]
        guide = self.mech.links[glink].guides[pair.guide]
        angle = guide.angle + (0.0 if glink == self.mech.frame else float(self.plans.motion.poses[glink][self.i, 2]))
        return np.array([math.cos(angle), math.sin(angle)])

    def _block(self, c, angle: float) -> None:
        c = np.asarray(c)
        u = np.array([math.cos(angle), math.sin(angle)])
        n = np.array([-u[1], u[0]])
        corners = [c + sx * 6.0 * u + sy * 3.5 * n for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        self.d.add(Line(tuple(tuple(map(float, p)) for p in corners), layer="links", width=0.7, closed=True))
        self.labels.mark(corners + corners[:1])

    def _curved(self, centre: np.ndarray, value: float, label: str, box) -> None:
        """A moment: an arc of 240° about ``centre`` (mm), CCW for a positive ``value``, its head at
        the arc's end, and its label."""
        r = 6.0
        sense = 1.0 if value > 0 else -1.0
        angles = np.radians(np.linspace(-30, 210, 25)) if sense > 0 else np.radians(np.linspace(210, -30, 25))
        pts = centre + r * np.column_stack([np.cos(angles), np.sin(angles)])
        self.d.add(Line(tuple(tuple(map(float, p)) for p in pts[:-1]), layer="forces", width=0.5))
        self.d.add(Arrow(tuple(map(float, pts[-3])), tuple(map(float, pts[-1])), layer="forces", width=0.5, head=2.5))
        self.labels.mark(pts)
        self.labels.add(centre + np.array([0.0, -r]), label, box, height=SMALL, prefer=(0.3, -1), gap=1.5)

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

    def _polygon(self, polygon: ForcePolygon, box, table_at) -> None:
        d, i, mu = self.d, self.i, self.mu_f
        title = Text((box[0] + 2, box[3] - 1), f"Force polygon of {polygon.step}, μ_F = {_num(mu)} N/mm", height=LABEL,
                     anchor=("left", "top"))
        d.add(title)
        self.labels.taken(title.box())
        d.region(f"polygon {polygon.step}", box)
        seq = self._sequence(polygon)
        chain = self._chain(polygon) / mu
        lo, hi = chain.min(axis=0), chain.max(axis=0)
        origin = np.array([(box[0] + box[2]) / 2, (box[1] + box[3]) / 2 - 4]) - (lo + hi) / 2
        centroid = origin + chain.mean(axis=0)
        ends: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        here = origin.copy()
        first_link_end = None
        rows = []
        for (label, kind, vector), _ in zip(seq, range(len(seq))):
            start, end = here, here + vector / mu
            here = end
            ends[f"{kind}:{label}"] = (start, end)
            if kind == "force" or kind in ("normal", "tangential"):
                pass
            part = {"normal": "n", "tangential": "t"}.get(kind, "")
            self._vector(polygon.step, label, kind, start, end, vector, name(label, part), box, centroid,
                         width=0.6 if kind == "force" else 0.45)
            rows.append([name(label, part), f"{float(np.hypot(*vector)) / mu:.1f}", _num(float(np.hypot(*vector)))])
            f = next((f for f in polygon.forces if f.label == label), None)
            if f is not None and len(polygon.links) == 2 and f.link == polygon.links[0] and kind != "normal" \
                    and (kind != "force" or not f.unknown):
                first_link_end = end
        for s in self.splits[polygon.step]:            # the whole reaction: Rⁿ + Rτ
            n_start = ends[f"normal:{s.label}"][0]
            t_start, t_end = ends[f"tangential:{s.label}"]
            n_end = ends[f"normal:{s.label}"][1]
            start, end = (n_start, t_end) if np.allclose(n_end, t_start) else (t_start, n_end)
            self._vector(polygon.step, s.label, "resultant", start, end, s.whole, name(s.label), box, centroid,
                         width=0.35)
            rows.append([name(s.label), f"{float(np.hypot(*s.whole)) / mu:.1f}", _num(float(np.hypot(*s.whole)))])
        if len(polygon.links) == 2 and len(polygon.internal) == 1 and first_link_end is not None:
            inner = polygon.internal[0]
            start = first_link_end
            self._vector(polygon.step, inner.label, "internal", start, start + inner.vector[i] / mu,
                         inner.vector[i], name(inner.label), box, centroid, width=0.35)
            rows.append([name(inner.label), f"{float(np.hypot(*inner.vector[i])) / mu:.1f}",
                         _num(float(np.hypot(*inner.vector[i])))])
        d.add(Circle(tuple(map(float, origin)), 0.8, layer="forces", filled=True))
        moments = [[f"{name(m.label)}, N·m", "—", _num(float(m.value[i]))] for m in polygon.moments]
        table(d, table_at, ["force", "length, mm", "value, N"], rows + moments, [26.0, 22.0, 28.0], height=SMALL,
              name=f"table {polygon.step}")

    def _vector(self, step, label, kind, start, end, value, text, box, centroid, width) -> None:
        start, end = tuple(map(float, start)), tuple(map(float, end))
        length = math.hypot(end[0] - start[0], end[1] - start[1])
        head = min(3.0, 0.4 * length + 0.5)
        if kind in ("resultant", "internal"):          # dashed: the shaft, then the head alone
            u = _unit(np.subtract(end, start))
            items = (self.d.add(Line((start, end), layer="forces", width=width, dashed=True)),
                     self.d.add(Arrow(tuple(map(float, np.asarray(end) - min(head, length) * u)), end,
                                      layer="forces", width=width, head=head)))
        else:
            items = (self.d.add(Arrow(start, end, layer="forces", width=width, head=head)),)
        self.sheet.vectors.append(DrawnVector(step, label, kind, start, end, np.asarray(value, float).copy(), items))
        self.labels.mark([start, end])
        if length >= LABELLED_MM:
            mid = (np.asarray(start) + np.asarray(end)) / 2
            self.labels.add(mid, text, box, height=SMALL, prefer=mid - centroid, gap=1.0)

    # -- the right column: lever, tables, scales, notes ------------------------------------------
    def _right(self, box) -> None:
        d, i = self.d, self.i
        plans = self.plans
        lever = plans.lever
        x0, y0, x1, y1 = box
        lever_box = (x0, y1 - 245, x1, y1)
        d.region("lever", lever_box)
        turned = {k: np.array([v[i, 1], -v[i, 0]]) for k, v in plans.velocity.images.items()}
        turned[POLE] = np.zeros(2)
        longest = max(float(np.hypot(*v.vector[i])) for v in plans.velocity.vectors)
        pts = np.array(list(turned.values()))
        span = np.ptp(pts, axis=0)
        room = (x1 - x0 - 2 * GROUP_MARGIN, lever_box[3] - lever_box[1] - 2 * GROUP_MARGIN - 8)
        # μ_v: the finest standard scale the lever fits its place at (its longest vector at least 60 mm)
        mu_v = nice_scale(max(span[0] / room[0], span[1] / room[1]))
        if longest / mu_v < 60.0:
            mu_v = standard_scale(longest, 60.0, 120.0)
            self.sheet.notes.append(f"the lever is drawn at μ_v = {_num(mu_v)} (m/s)/mm, larger than its place "
                                    "allows")
        self.sheet.mu_v = mu_v
        title = Text((x0 + 2, y1 - 1), f"Zhukovsky's lever: the velocity plan turned 90° clockwise, "
                     f"μ_v = {_num(mu_v)} (m/s)/mm", height=LABEL, anchor=("left", "top"))
        d.add(title)
        self.labels.taken(title.box())
        d.use(Scale("μ_v", mu_v, "(m/s)/mm"))
        centre_q = (pts.min(axis=0) + pts.max(axis=0)) / 2
        view = d.view(Scale("μ_v", mu_v, "(m/s)/mm"), origin=((x0 + x1) / 2, (lever_box[1] + lever_box[3]) / 2 - 4),
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
        d.add(Circle(p, 0.8, layer="plans", filled=True))
        self.labels.add(p, "p", lever_box, height=LABEL, prefer=(-1, -1))
        for label, q in turned.items():
            if label == POLE or label in frame_points or np.hypot(*q) / mu_v < 0.5:
                continue
            at = view(q)
            d.add(Circle(at, 0.6, layer="plans", filled=True))
            self.labels.add(at, _image(label), lever_box, height=SMALL, prefer=(1, 1))
        largest = max([float(np.hypot(*f.force[i])) for f in lever.forces] + [0.0])
        for f in lever.forces:
            size = float(np.hypot(*f.force[i]))
            if size <= 1e-9 * largest:
                continue
            start = np.array(view(turned[f.point]))
            end = start + _arrow_mm(size, largest) * _unit(f.force[i])
            d.add(Arrow(tuple(start), tuple(end), layer="forces", width=0.5, head=3.0))
            self.labels.mark([start, end])
            self.labels.add(end, name(f.label), lever_box, height=SMALL, prefer=_unit(f.force[i]))
        # the lever's table
        omega = float(lever.omega[i])
        biggest = max([abs(float(f.moment[i])) for f in lever.forces]
                      + [abs(float(m.contribution[i])) for m in lever.moments] + [1e-300])

        def zeroed(x: float) -> str:                    # round-off of a force through the pole reads 0
            return _num(x if abs(x) > 1e-12 * biggest else 0.0)

        rows = []
        for f in lever.forces:
            size = float(np.hypot(*f.force[i]))
            moment = float(f.moment[i])
            arm = abs(moment) / size / mu_v if size > 0 else 0.0
            rows.append([f"{name(f.label)} at {_image(f.point)}", _num(size), f"{arm:.1f}", zeroed(moment)])
        for m in lever.moments:
            rows.append([f"{name(m.label)}·ω{m.link.translate(_SUB)}", _num(float(m.value[i])),
                         "—", zeroed(float(m.contribution[i]))])
        top = lever_box[1] - 3
        tb = table(d, (x0, top), ["force at its image", "F, N", "h, mm", "F·h·μ_v, N·m/s"], rows,
                   [44.0, 24.0, 16.0, 34.0], height=SMALL, name="lever table")
        total = sum(float(f.moment[i]) for f in lever.forces) + sum(float(m.contribution[i]) for m in lever.moments)
        mb_lever = float(lever.balancing_moment[i])
        inputs = [p for p in plans.polygons if p.step.startswith("I(")]
        mb_poly = float(next(m.value[i] for m in inputs[0].moments if m.kind == "balancing"))
        self.sheet.mb_lever, self.sheet.mb_polygons = mb_lever, mb_poly
        formula = Text((x0, tb[1] - 2), f"Mb = −ΣM/ω₁ = −({_num(total)})/({_num(omega)}) = {_num(mb_lever)} N·m",
                       height=SMALL, anchor=("left", "top"))
        d.add(formula)
        self.labels.taken(formula.box())
        diff = (mb_lever - mb_poly) / abs(mb_poly) * 100.0 if mb_poly != 0 else 0.0
        mb = table(d, (x0, formula.box()[1] - 3), ["balancing moment Mb", "Mb, N·m", "difference, %"],
                   [["by the force polygons", _num(mb_poly), ""],
                    ["by Zhukovsky's lever", _num(mb_lever), _num(round(diff, 3)) if abs(diff) >= 1e-3 else "0.000"]],
                   [50.0, 28.0, 28.0], height=SMALL, name="balancing moment")
        sc = scales_table(d, (x0, mb[1] - 4), height=SMALL)
        notes = ["Arrows on the groups and on the lever show the lines and senses of the forces, not to "
                 "scale: the polygons are drawn at μ_F and their tables give the values."] + self.sheet.notes
        text = "\n".join(_wrapped(f"{k + 1}. {line}", 0.7 * SMALL, x1 - x0 - (sc[2] - x0) - 6)
                         for k, line in enumerate(notes))
        note = Text((sc[2] + 4, sc[3]), "Notes:\n" + text, height=SMALL, anchor=("left", "top"))
        d.add(note)


def _wrapped(text: str, char_mm: float, width_mm: float) -> str:
    chars = max(int(width_mm / char_mm), 10)
    lines: list[str] = []
    for word in text.split():
        if lines and len(lines[-1]) + 1 + len(word) <= chars:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return "\n".join(lines)


def _image(label: str) -> str:
    """The image of a point on the lever in lower case: ``B`` -> b, ``S2`` -> s₂, ``A(3)`` -> a₃."""
    m = re.fullmatch(r"([A-Za-z]+)(\d*)(?:\((.+)\))?('*)", label)
    if not m:
        return label.lower()
    letters, digits, link, primes = m.groups()
    return letters.lower() + (digits + (link or "")).translate(_SUB) + primes
