"""The parts of the kinetostatics sheet (:mod:`.kinetostatics_sheet`) that are not its layout:
what a drawn polygon vector and a split reaction are, the numbers read from the plans at the drawn
position (where a force or pair acts, the split ``R = Rⁿ + Rτ`` of a dyad's outer reactions), the
names and numbers as written on the sheet, and the label placer that keeps texts off each other and
off the lines drawn.
"""

from __future__ import annotations

import math
import re
import textwrap
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...kinetostatics.plans import (
    ForcePolygon,
    Plans,
    PolygonForce,
    build_plans,
    require_crank_input,
)
from ...model.mechanism import Revolute
from ...model.scheme import section_of
from ...report.results import forces_results
from .model import Drawing, Text

__all__ = ["DrawnVector", "ReactionSplit", "Labels", "Sizes", "analysis", "force_point", "global_point", "image", "name",
           "num", "pair_point", "sizes", "split_reactions", "unit",
           "wrapped"]

#: text heights: headings, labels, tables, mm
HEADING, LABEL, SMALL = 5.0, 3.5, 2.5
#: the width of A1 landscape, mm: a smaller paper's lengths are in proportion
A1_WIDTH = 841.0
#: the clear margin a label keeps from the lines drawn, mm
CLEAR_MM = 1.2
#: the clear margin between two labels, mm
SPACING_MM = 1.0

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


@dataclass(frozen=True)
class Sizes:
    """The text heights of a sheet on one paper, mm: ``heading`` (the sheet's heading and the
    boxes' titles), ``text`` (everything else), ``tables`` (the heights a table is tried at,
    largest first); ``k`` the paper's width over A1's (the layout's lengths are in proportion)."""

    heading: float
    text: float
    tables: tuple[float, ...]
    k: float


def sizes(drawing: Drawing) -> Sizes:
    """A1: headings 5 mm, text 3.5 mm (tables 3.5 or 2.5 mm); A2, A3: headings 3.5 mm, text 2.5 mm."""
    k = drawing.size[0] / A1_WIDTH
    return Sizes(5.0, 3.5, (3.5, 2.5), k) if k > 0.9 else Sizes(3.5, 2.5, (2.5,), k)


# ----------------------------------------------------------------------------------------------
# the numbers
# ----------------------------------------------------------------------------------------------


def analysis(mech, position: int, omega: float | None) -> tuple[Plans, int, list[str]]:
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


def global_point(motion, link: str, local, i: int) -> np.ndarray:
    """Global position ``(2,)``, m, of the point ``local`` of ``link`` at position ``i``."""
    if link == motion.mechanism.frame:
        return np.asarray(local, float)
    return motion.poses[link][i, :2] + motion.arm(link, np.asarray(local, float))[i]


def pair_point(motion, pair: str, link: str, i: int) -> np.ndarray:
    """Where the pair ``pair`` acts on ``link``, m (a prismatic pair: at its slider's point)."""
    mech = motion.mechanism
    p = mech.pairs[pair]
    owner = link if p.point in mech.links[link].points else next(k for k in p.links if p.point in mech.links[k].points)
    return global_point(motion, owner, mech.links[owner].points[p.point], i)


def force_point(plans: Plans, f: PolygonForce, i: int) -> np.ndarray:
    """Where the polygon force ``f`` acts, m."""
    motion = plans.motion
    if f.kind == "reaction":
        return pair_point(motion, f.pair, f.link, i)
    for t in plans.reactions.terms:
        if t.link == f.link and t.label == f.label:
            return global_point(motion, t.link, t.local, i)
    raise KeyError(f"no load {f.label} on link {f.link}")


def inner_revolute(mech, polygon: ForcePolygon) -> dict[str, str]:
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
    inner = inner_revolute(mech, polygon)
    out = []
    for f in polygon.forces:
        if not (f.kind == "reaction" and f.unknown and f.link in inner and isinstance(mech.pairs[f.pair], Revolute)):
            continue
        b = pair_point(plans.motion, f.pair, f.link, i)
        c = pair_point(plans.motion, inner[f.link], f.link, i)
        length = float(np.hypot(*(c - b)))
        if length <= 1e-9 * mech.size:
            continue
        e_n = (c - b) / length
        e_t = np.array([-e_n[1], e_n[0]])
        moment = 0.0                                   # about C, of every other force and moment on the link
        for g in polygon.on_link(f.link):
            if g.label == f.label or g.pair == inner[f.link]:
                continue
            r = force_point(plans, g, i) - c
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

SUB = str.maketrans("0123456789,", "₀₁₂₃₄₅₆₇₈₉‚")


def name(label: str, part: str = "") -> str:
    """A polygon label as written: ``R[2,1]`` -> R₂₁, ``G2`` -> G₂, ``Fi2`` -> Fᵢ₂, ``Mi2`` ->
    Mᵢ₂; ``part`` ``"n"`` / ``"t"`` gives Rⁿ₂₁ / Rτ₂₁."""
    top = {"n": "ⁿ", "t": "τ", "": ""}[part]
    m = re.fullmatch(r"([RM])\[(.+?),(.+?)\](?:\((.+)\))?", label)
    if m:
        head, a, b, pair = m.groups()
        sub = (a + b) if len(a) == len(b) == 1 else f"{a},{b}"
        return f"{head}{top}{sub.translate(SUB)}" + (f"({pair})" if pair else "")
    m = re.fullmatch(r"(G|Fi|Mi|Mb)(\d+)", label)
    if m:
        head, link = m.groups()
        return head[0] + {"i": "ᵢ", "b": "b"}.get(head[1:], "") + link.translate(SUB)
    return label


def num(x: float) -> str:
    """4 significant digits (whole numbers from 10 000 up), a true minus, no -0."""
    text = f"{x:.0f}" if 1e4 <= abs(x) < 1e9 else f"{x:.4g}"
    return ("0" if float(text) == 0 else text).replace("-", "−")


# ----------------------------------------------------------------------------------------------
# placing labels
# ----------------------------------------------------------------------------------------------


class Labels:
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
        for ring in (gap, gap + 1.5, gap + 3.0, gap + 5.0, gap + 8.0, gap + 12.0, gap + 17.0):
            for angle in np.radians(np.arange(0, 360, 22.5)):
                d = np.array([math.cos(angle), math.sin(angle)])
                h = ("left" if d[0] > 0.3 else "right" if d[0] < -0.3 else "center")
                v = ("bottom" if d[1] > 0.3 else "top" if d[1] < -0.3 else "middle")
                item = Text((float(at[0] + ring * d[0]), float(at[1] + ring * d[1])), text, height=height,
                            layer=layer, anchor=(h, v))
                box = item.box()
                spaced = (box[0] - SPACING_MM, box[1] - SPACING_MM, box[2] + SPACING_MM, box[3] + SPACING_MM)
                if not inside(box, within) or any(overlap(spaced, b) for b in self.boxes):
                    continue
                clear = (box[0] - CLEAR_MM, box[1] - CLEAR_MM, box[2] + CLEAR_MM, box[3] + CLEAR_MM)
                hits = int(np.sum((marks[:, 0] > clear[0]) & (marks[:, 0] < clear[2]) & (marks[:, 1] > clear[1])
                                  & (marks[:, 1] < clear[3]))) if len(marks) else 0
                cost = 100.0 * hits + ring + 2.0 * (1.0 - float(d @ prefer))
                if cost < best_cost:
                    best, best_cost = item, cost
            if best is not None and best_cost < 100.0:
                break
        if best is None:
            return None
        self.boxes.append(best.box())
        return self.drawing.add(best)


def inside(box, outer) -> bool:
    return box[0] >= outer[0] and box[1] >= outer[1] and box[2] <= outer[2] and box[3] <= outer[3]


def overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    n = float(np.hypot(*v))
    return v / n if n > 0 else np.array([1.0, 0.0])



def wrapped(text: str, char_mm: float, width_mm: float) -> str:
    """``text`` broken at spaces into lines of at most ``width_mm`` mm at ``char_mm`` mm a
    character (10 characters at least; a longer word keeps its line)."""
    chars = max(int(width_mm / char_mm), 10)
    return "\n".join(textwrap.wrap(text, chars, break_long_words=False, break_on_hyphens=False))


def image(label: str) -> str:
    """The image of a point on the lever in lower case: ``B`` -> b, ``S2`` -> s₂, ``A(3)`` -> a₃."""
    m = re.fullmatch(r"([A-Za-z]+)(\d*)(?:\((.+)\))?('*)", label)
    if not m:
        return label.lower()
    letters, digits, link, primes = m.groups()
    return letters.lower() + (digits + (link or "")).translate(SUB) + primes
