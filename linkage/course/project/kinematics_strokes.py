"""The strokes of a kinematics sheet's output: which stroke works, and how they are marked.

:func:`stroke_senses` tells the working stroke from the idle one (from the output's load in
``[[loads.forces]]``, else the slower stroke); :func:`stroke_arrows` draws each stroke's travel of
the output point as a dimension arrow beyond its position numbers, and :func:`crank_arcs` the
crank angles of the two strokes as arcs about the crank's pivot (φ_w, φ_i).
:func:`retraced` and :func:`across` describe a trajectory on paper (a slider's runs back over
itself).
"""

from __future__ import annotations

import math

import numpy as np

from ...kinetostatics.loads import CycleTable, StrokeDiagram, loads_of
from ...model.mechanism import Revolute
from .kinematics_data import KinematicsData
from .model import Arrow, Drawing, Line

__all__ = ["retraced", "across", "stroke_senses", "stroke_arrows", "crank_arcs"]


def retraced(path: np.ndarray) -> bool:
    """Whether a closed trajectory (mm) runs back over itself (a slider's, a rocker's point): the
    area it encloses is under 2 % of its extent squared."""
    if len(path) < 3:
        return True
    x, y = path[:, 0], path[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    extent = float(np.max(np.ptp(path, axis=0)))
    return area <= 0.02 * extent ** 2


def across(path: np.ndarray) -> np.ndarray:
    """The unit vector across a path (mm): normal to its principal direction, pointing up (or right)."""
    d = np.linalg.svd(path - path.mean(axis=0), full_matrices=False)[2][0]
    n = np.array([-d[1], d[0]])
    return n if (n[1] > 1e-9 or (abs(n[1]) <= 1e-9 and n[0] > 0)) else -n


def stroke_senses(data: KinematicsData) -> dict | None:
    """The output's strokes: ``working`` (+1: the output quantity increases on the working
    stroke), ``why`` (words), ``leaving`` (the sense in which the output leaves each table
    row, ±1), ``rows`` (the sweep's rows of the working stroke's start and end). None when the
    output has no extremes on the table's travel."""
    if set(data.extremes) != {"max", "min"}:
        return None
    mech, motion = data.mech, data.motion
    q = motion.quantity(mech.output.quantity)[0]
    full = mech.coordinate.is_angle and mech.input_range is None
    nxt = np.concatenate([q[1:-1], q[:1], q[1:2]]) if full else np.concatenate([q[1:], [2 * q[-1] - q[-2]]])
    change = np.where(np.isfinite(nxt - q), nxt - q, 0.0)
    leaving = np.where(change >= 0, 1, -1)
    working, why = None, ""
    for f in getattr(loads_of(mech), "forces", ()):
        load = f.force
        if getattr(load, "quantity", None) != mech.output.quantity:
            continue
        if isinstance(load, StrokeDiagram):
            working, why = int(load.working), "as the load diagram of [[loads.forces]] declares"
        elif isinstance(load, CycleTable):
            mag = np.abs(np.asarray(load.values, float))
            peak = int(np.argmax(mag))
            if peak > 0 and np.isfinite(q[peak % len(q)]) and np.isfinite(q[peak - 1]):
                working = 1 if q[peak % len(q)] - q[peak - 1] >= 0 else -1
                why = "where the useful resistance of [[loads.forces]] acts"
        if working is not None:
            break
    if working is None:
        rows = data.extremes
        t = data.psi
        up = abs(float(t[rows["max"]] - t[rows["min"]]))
        up = up if rows["max"] > rows["min"] else abs(float(t[-1] - t[0])) - up
        working = 1 if up >= abs(float(t[-1] - t[0])) - up else -1
        why = "the slower stroke (the scheme declares no load on its output)"
    start, end = ("min", "max") if working > 0 else ("max", "min")
    return {"working": working, "why": why, "leaving": leaving,
            "rows": (data.extremes[start], data.extremes[end])}


def stroke_arrows(drawing: Drawing, data: KinematicsData, view, point: str, strokes: dict, normal, edges: dict,
                   placer, h: float) -> None:
    """The working stroke's travel of the output point as an arrow beyond its numbers, the idle
    stroke's opposite, each named with the output's stroke (m, or degrees for an angle)."""
    path = data.sweep.point(point)
    a, b = strokes["rows"]
    pa, pb = np.array(view.paper(path[a])), np.array(view.paper(path[b]))
    n = np.asarray(normal, float)
    centre = np.mean([view.paper(p) for p in data.motion.point(point)[data.rows]], axis=0)
    value = data.sweep.quantity(data.mech.output.quantity)[0]
    stroke = abs(float(value[data.extremes["max"]] - value[data.extremes["min"]]))
    size = f"{math.degrees(stroke):.1f}°" if data.mech.output.quantity.endswith(".theta") else f"H = {stroke:.4g} m"
    for side, (s, e), words in ((1, (pa, pb), "working stroke"), (-1, (pb, pa), "idle stroke")):
        off = edges.get(side, 2 * h) + 2.5
        s_off = s + side * n * max(off + side * float(np.dot(centre - s, n)), off)
        e_off = e + side * n * max(off + side * float(np.dot(centre - e, n)), off)
        shift = (s_off - s + e_off - e) / 2
        s_off, e_off = s + shift, e + shift
        if np.hypot(*(e_off - s_off)) < 6.0:
            continue
        drawing.add(Arrow(tuple(s_off), tuple(e_off), layer="dimensions", width=0.35, head=3.0))
        for p, q in ((s, s_off), (e, e_off)):
            drawing.add(Line((tuple(p + (q - p) * 0.15), tuple(q + (q - p) / max(np.hypot(*(q - p)), 1e-9) * 1.5)),
                             layer="dimensions", width=0.18))
        mid = (s_off + e_off) / 2
        placer.place(tuple(mid), f"{words}, {size}", h, prefer=side * n, rings=(0.5, 1.0, 1.8, 3.0))


def crank_arcs(drawing: Drawing, data: KinematicsData, view, strokes: dict, placer, h: float) -> None:
    """Arcs about the crank's pivot over the crank angles of the working stroke (φ_w) and of the
    idle stroke (φ_i), arrowed in the direction of rotation."""
    mech, sweep = data.mech, data.sweep
    crank = mech.inputs[0]
    pins = [p for p in mech.pairs.values() if isinstance(p, Revolute) and crank in p.links]
    pivot = next((p for p in pins if mech.frame in p.links), None)
    tip = next((p for p in pins if mech.frame not in p.links), None)
    if pivot is None or tip is None:
        return
    o = sweep.point(pivot.point)[0]
    rel = sweep.point(tip.point) - o
    angle = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
    radius_mm = float(np.nanmax(np.hypot(rel[:, 0], rel[:, 1]))) / view.scale.value
    last = len(angle) - 1
    a, b = strokes["rows"]
    spans = {"working": (a, b), "idle": (b, a)}
    for k, (name, (r0, r1)) in enumerate(spans.items()):
        rows = np.arange(r0, r1 + 1) if r1 >= r0 else np.concatenate([np.arange(r0, last), np.arange(0, r1 + 1)])
        turned = np.unwrap(angle[rows])
        sweep_deg = abs(math.degrees(float(turned[-1] - turned[0])))
        if sweep_deg < 2.0:
            continue
        r = radius_mm + (6.0 + 5.0 * k) * (1.0 if h >= 3.5 else 0.8)
        t = np.linspace(float(turned[0]), float(turned[-1]), max(8, int(sweep_deg / 3)))
        centre = np.array(view.paper(o))
        arc = centre + r * np.column_stack([np.cos(t), np.sin(t)])
        drawing.add(Line(tuple(map(tuple, arc[:-1])), layer="dimensions", width=0.3))
        drawing.add(Arrow(tuple(arc[-2]), tuple(arc[-1]), layer="dimensions", width=0.3, head=2.5))
        mid = arc[len(arc) // 2]
        symbol = "φ_w" if name == "working" else "φ_i"
        placer.place(tuple(mid), f"{symbol} = {sweep_deg:.1f}°", 0.9 * h, prefer=mid - centre,
                     rings=(0.4, 0.9, 1.6, 2.5, 4.0))
