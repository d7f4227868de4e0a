"""Labels that collide with nothing: the one placer of every picture's texts.

A :class:`Label` is a text with the places it may take: candidate boxes around anchors, each with
a preference. :func:`place_labels` writes the labels one after the other, each at its candidate
of least cost: outside the bounds, on a label placed before, on a line (by the length of line the
box covers; light lines cost less), on a disc, with its centre inside an area (the obstacles, a
:class:`Drawn`), plus the candidate's own preference (far from its anchor, away from the side it
should be on). A label whose best place still costs too much may be left out. Deterministic.

The mechanism's drawings, films and hodographs place their point labels with it
(:func:`~linkage.report.drawing.place_point_labels`, in pixels), the plans their point and vector
labels (:mod:`linkage.report.plan_drawings`, in mm of paper), each with its own candidates and
weights. The measures the costs are made of are here too: :func:`clip_lengths` (length of
segments inside boxes), :func:`points_inside` (points inside a polygon).

>>> import numpy as np
>>> clip_lengths(np.array([[0.0, 0.0, 2.0, 0.0]]), np.array([[0.5, -1.0, 1.0, 1.0], [3.0, -1.0, 4.0, 1.0]]))
array([0.5, 0. ])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple, Sequence

import numpy as np

__all__ = ["Drawn", "Label", "Place", "place_labels", "clip_lengths", "points_inside"]


class Drawn:
    """Obstacles of a drawing for the label placement: lines, discs and areas, in data coordinates
    (in the plane of :func:`place_labels` when given to it)."""

    def __init__(self):
        self.segments: list[np.ndarray] = []   # (M, 4) x0 y0 x1 y1
        self.light: list[np.ndarray] = []      # segments labels may cross at a small cost
        self.discs: list[tuple[np.ndarray, float]] = []
        self.areas: list[np.ndarray] = []      # polygons a label should not sit inside

    def polyline(self, pts: np.ndarray, closed: bool = False, light: bool = False) -> None:
        pts = np.asarray(pts, dtype=float)
        if closed and len(pts) > 2:
            pts = np.vstack([pts, pts[:1]])
        if len(pts) >= 2:
            seg = np.hstack([pts[:-1], pts[1:]])
            (self.light if light else self.segments).append(seg[np.all(np.isfinite(seg), axis=1)])


@dataclass
class Label:
    """A text to place and the places it may take, in the placer's plane.

    Candidate ``k`` is the box of the text (its size measured, with a margin) that starts
    ``gaps[k]`` from ``anchor`` in the direction ``directions[k]`` (the box's nearest side that
    far along the direction), and costs ``preference[k]`` before what it covers.

    Attributes
    ----------
    text : matplotlib Text
        The label, already in the axes (it is measured, and removed if it is left out).
    anchor : array
        Where the candidates start from: ``(2,)``, or ``(K, 2)`` one per candidate.
    directions : array
        ``(K, 2)`` unit vectors.
    gaps : array
        ``(K,)`` distances from the anchor to the box.
    preference : array
        ``(K,)`` cost of each candidate before collisions.
    drop : float
        Leave the label out when its best candidate costs at least this much (never by default).
    """

    text: Any
    anchor: np.ndarray
    directions: np.ndarray
    gaps: np.ndarray
    preference: np.ndarray
    drop: float = math.inf


class Place(NamedTuple):
    """Where :func:`place_labels` put a label: the centre of its box and the box's size."""

    centre: np.ndarray
    width: float
    height: float


def place_labels(labels: Sequence[Label], drawn: Drawn, bounds: tuple[float, float, float, float], renderer, *,
                 per_px: float = 1.0, line_cost: float = 60.0, light_cost: float = 6.0, disc_cost: float = 3000.0,
                 area_cost: float = 800.0, clearance: float = 0.0) -> list[Place | None]:
    """Place ``labels`` in turn, each at its candidate of least cost.

    The cost of a candidate is its preference, plus 1e5 per unit it reaches outside ``bounds``
    (xmin, ymin, xmax, ymax), 1e4 (and 100 per unit² of overlap) for each label placed before
    that it overlaps or comes closer to than ``clearance``, ``line_cost`` per unit of
    ``drawn.segments`` inside its box (``light_cost`` of ``drawn.light``), ``disc_cost`` for each
    disc of ``drawn.discs`` that it comes nearer than the disc's radius, ``area_cost`` for each
    area of ``drawn.areas`` its centre lies in.

    Parameters
    ----------
    labels : sequence of Label
    drawn : Drawn
        The obstacles, in the placer's plane (pixels, or the data's units).
    bounds : (xmin, ymin, xmax, ymax)
        Where the labels must stay.
    renderer
        The figure's renderer (the texts are measured with it).
    per_px : float
        Units of the placer's plane per pixel (1 in pixels).
    line_cost, light_cost, disc_cost, area_cost, clearance
        The weights above.

    Returns
    -------
    list of Place or None
        Per label, in order: where it went (the caller moves its text there), or None when it
        was left out (its text removed).
    """
    x0, y0, x1, y1 = bounds
    heavy, light = _stacked(drawn.segments), _stacked(drawn.light)
    placed = np.zeros((0, 4))
    out: list[Place | None] = []
    for label in labels:
        bb = label.text.get_window_extent(renderer)
        w, h = (bb.width + 2) * per_px, (bb.height + 1) * per_px
        d = np.asarray(label.directions, dtype=float)
        centre = label.anchor + (label.gaps + np.abs(d[:, 0]) * w / 2 + np.abs(d[:, 1]) * h / 2)[:, None] * d
        boxes = np.hstack([centre - [w / 2, h / 2], centre + [w / 2, h / 2]])
        cost = np.array(label.preference, dtype=float)
        outside = (np.maximum(0, x0 - boxes[:, 0]) + np.maximum(0, boxes[:, 2] - x1) +
                   np.maximum(0, y0 - boxes[:, 1]) + np.maximum(0, boxes[:, 3] - y1))
        cost += 1e5 * outside
        for q in placed:
            ow = np.minimum(boxes[:, 2], q[2]) - np.maximum(boxes[:, 0], q[0])
            oh = np.minimum(boxes[:, 3], q[3]) - np.maximum(boxes[:, 1], q[1])
            hit = (ow > -clearance) & (oh > -clearance)
            cost += np.where(hit, 1e4 + 100 * np.maximum(ow, 0) * np.maximum(oh, 0), 0.0)
        cost += line_cost * clip_lengths(heavy, boxes) + light_cost * clip_lengths(light, boxes)
        for cc, rr in drawn.discs:
            nx = np.clip(cc[0], boxes[:, 0], boxes[:, 2])
            ny = np.clip(cc[1], boxes[:, 1], boxes[:, 3])
            cost += np.where(np.hypot(nx - cc[0], ny - cc[1]) < rr, disc_cost, 0.0)
        for poly in drawn.areas:
            cost += np.where(points_inside(poly, centre), area_cost, 0.0)
        k = int(np.argmin(cost))
        if cost[k] >= label.drop:
            label.text.remove()
            out.append(None)
            continue
        placed = np.vstack([placed, boxes[k]])
        out.append(Place(centre[k], w, h))
    return out


def _stacked(segments: list[np.ndarray]) -> np.ndarray:
    """The segments of a :class:`Drawn`'s list as one ``(M, 4)`` array."""
    segments = [x for x in segments if len(x)]
    return np.vstack(segments) if segments else np.zeros((0, 4))


def clip_lengths(seg: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Total length of the segments ``(M, 4)`` inside each axis-aligned box of ``boxes`` ``(K, 4)``
    (xmin, ymin, xmax, ymax), by Liang-Barsky clipping: ``(K,)``."""
    if not len(seg):
        return np.zeros(len(boxes))
    x0, y0, x1, y1 = (seg[:, k][None, :] for k in range(4))
    xmin, ymin, xmax, ymax = (boxes[:, k][:, None] for k in range(4))
    dx, dy = x1 - x0, y1 - y0
    t0 = np.zeros((len(boxes), len(seg)))
    t1 = np.ones_like(t0)
    ok = np.ones_like(t0, dtype=bool)
    for p, q in ((-dx, x0 - xmin), (dx, xmax - x0), (-dy, y0 - ymin), (dy, ymax - y0)):
        p = np.broadcast_to(p, t0.shape)
        zero = np.abs(p) < 1e-12
        ok &= ~(zero & (q < 0))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(zero, 0.0, q / np.where(zero, 1.0, p))
        t0 = np.where(~zero & (p < 0), np.maximum(t0, r), t0)
        t1 = np.where(~zero & (p > 0), np.minimum(t1, r), t1)
    inside = ok & (t1 > t0)
    return np.sum(np.where(inside, (t1 - t0) * np.hypot(dx, dy), 0.0), axis=1)


def points_inside(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Which of the points ``(N, 2)`` lie inside the polygon ``poly`` ``(V, 2)``."""
    from matplotlib.path import Path

    pts = np.atleast_2d(pts)
    if len(poly) < 3 or not len(pts):
        return np.zeros(len(pts), bool)
    return Path(poly).contains_points(pts)
