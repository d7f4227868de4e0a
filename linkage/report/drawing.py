"""The mechanism drawn to scale (equal aspect, axes in m), fully inside the frame.

- :func:`draw_mechanism` -- one position: links as lines and polygons, revolute pairs as circles,
  sliders as blocks along their guides, guides and slots, a driven pair between moving links as a
  cylinder (barrel and rod), frame pivots and guides hatched, point labels placed where they
  collide with nothing, trajectories of named points;
- :func:`draw_positions` -- several positions side by side at one common scale.

The pieces the film (:mod:`linkage.report.animation`), the hodographs and the course sheets share:
the drawable geometry of a motion (:class:`Geometry`) and what one position holds
(:class:`Scene`), the frame's supports and hatched guides (:func:`support`, :func:`rail_hatch`,
:data:`SUPPORT_DIRECTIONS`), the axis limits and the figure of a drawing (:func:`drawing_limits`,
:func:`figure_for`), the drawing of a scene (:func:`draw_scene`, :func:`moving_artists`,
:func:`add_artists`), what its labels keep clear of (:func:`scene_obstacles`) and where they go
(:func:`place_point_labels`).

Needs matplotlib (the ``plot`` extra): without it the functions raise
:class:`~linkage.report.style.PlotExtraMissing`.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import numpy as np, linkage
>>> motion = linkage.analyze(linkage.load("slotted_link_two_dyad"), np.radians([30.0]))
>>> ax = draw_mechanism(motion, 0)
>>> ax.get_xlabel(), ax.get_ylabel()
('x, m', 'y, m')
>>> matplotlib.pyplot.close("all")
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from assur.base import global_point

from ..errors import InputError
from ..kinematics.motion import input_sweep
from ..model.mechanism import Prismatic
from .labels import Drawn, Label, place_labels, points_inside
from .style import FONT, LINK_COLOURS, PAGE_WIDTH, SMALL, new_figure, pyplot
from .words import input_word, position_caption, trajectory_note

__all__ = ["draw_mechanism", "draw_positions", "Scene", "Geometry", "convex_hull", "support", "rail_hatch",
           "SUPPORT_DIRECTIONS", "scene_samples", "drawing_limits", "figure_for", "draw_scene", "PIN", "DOT",
           "scene_obstacles", "moving_artists", "add_artists", "place_point_labels"]


@dataclass
class Scene:
    """What a drawing of one position holds, in data coordinates (m)."""

    points: dict[str, np.ndarray] = field(default_factory=dict)      # named point -> (2,)
    bodies: list[tuple[str, np.ndarray]] = field(default_factory=list)  # (link, polygon or polyline)
    slots: list[tuple[str, np.ndarray]] = field(default_factory=list)   # (link, 2x2) guides of moving links
    rails: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)  # (2x2 line, hatch side unit normal)
    blocks: list[tuple[str, np.ndarray, float, bool]] = field(default_factory=list)  # (link, centre, angle, on frame)
    pins: list[tuple[str, np.ndarray]] = field(default_factory=list)    # revolute pairs
    pivots: list[tuple[np.ndarray, float]] = field(default_factory=list)  # frame pivots: point, support direction
    dots: list[str] = field(default_factory=list)                       # named points that are no pair's
    trajectories: list[tuple[str, str, np.ndarray]] = field(default_factory=list)  # (point, link, (M, 2))
    #: driven prismatic pairs between moving links (cylinders): (barrel link, rod link, barrel
    #: rectangle (4, 2), rod from its piston to its end (2, 2), piston across the barrel (2, 2))
    cylinders: list[tuple[str, str, np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=list)


def _global(motion, link: str, local, rows) -> np.ndarray:
    return global_point(motion.poses[link][rows], local)


def _local_along(pose: np.ndarray, guide, p: np.ndarray) -> np.ndarray:
    """Coordinates along a guide (in its link, pose ``(N, 3)``) of global points ``p`` ``(N, 2)``."""
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    d = p - pose[:, :2]
    local = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    return (local - np.asarray(guide.point)) @ np.array(guide.direction)


def convex_hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull (counter-clockwise, monotone chain) of points ``(N, 2)``."""
    pts = np.unique(np.round(pts, 15), axis=0)
    if len(pts) <= 2:
        return pts
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    pts = pts[order]

    def half(seq):
        out: list[np.ndarray] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-1] - out[-2], p - out[-2]) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _extent(values: np.ndarray, fallback: float) -> tuple[float, float]:
    v = values[np.isfinite(values)]
    return (float(v.min()), float(v.max())) if v.size else (fallback, fallback)


class Geometry:
    """The drawable geometry of a motion: what is drawn at a position, and the sizes of symbols."""

    def __init__(self, motion, positions: Sequence[int], trajectories: Sequence[str] = ()):
        self.motion = motion
        self.mech = mech = motion.mechanism
        self.sweep = input_sweep(mech)
        self.trajectories = list(trajectories)
        for name in self.trajectories:
            if name not in mech.point_names:
                raise InputError(f"no point {name!r} to draw the trajectory of; points: {mech.point_names}")
        for i in positions:
            if not np.all([np.all(np.isfinite(motion.poses[k][i])) for k in motion.poses]):
                raise InputError(f"position {i + 1} ({mech.coordinate.describe([motion.phi[i]])}) is not assembled: "
                                 "nothing to draw")
        # the scale of the drawing: the points at the drawn positions and the sliders' travel
        pts = [self._all_points(i) for i in positions]
        pts += [self._sweep_points(name) for name in self.trajectories]
        allp = np.vstack(pts)
        allp = allp[np.all(np.isfinite(allp), axis=1)]
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        self.span = float(max(hi - lo)) or mech.size
        self.unit = 0.032 * self.span    # size of the symbols (pins, blocks, supports), m
        self.travel = self._travel()

    def _all_points(self, i: int) -> np.ndarray:
        m = self.motion
        # the links placed (a cylinder's driver "K.s" has a pose but is no link: no points)
        return np.array([_global(m, lk, local, slice(i, i + 1))[0] for lk in m.poses if lk in self.mech.links
                         for local in self.mech.links[lk].points.values()] +
                        [np.asarray(p) for p in self.mech.links[self.mech.frame].points.values()]).reshape(-1, 2)

    def _sweep_points(self, name: str) -> np.ndarray:
        link = self.mech.point_link(name)
        return _global(self.sweep, link, self.mech.links[link].points[name], slice(None))

    def _travel(self) -> dict[tuple[str, str], tuple[float, float]]:
        """(guide link, guide) -> range of the sliders' points along the guide over the turn."""
        mech, out = self.mech, {}
        for pair in mech.pairs.values():
            if not isinstance(pair, Prismatic):
                continue
            glink = pair.links[0]
            guide = mech.links[glink].guides[pair.guide]
            along = []
            for m in (self.sweep, self.motion):
                slider = pair.links[1]
                if slider not in m.poses or (glink != mech.frame and glink not in m.poses):
                    continue
                p = _global(m, slider, mech.links[slider].points[pair.point], slice(None))
                pose = np.zeros((len(p), 3)) if glink == mech.frame else m.poses[glink]
                along.append(_local_along(pose, guide, p))
            values = np.concatenate(along) if along else np.array([0.0])
            lo, hi = _extent(values, 0.0)
            old = out.get((glink, pair.guide))
            out[(glink, pair.guide)] = (lo, hi) if old is None else (min(lo, old[0]), max(hi, old[1]))
        return out

    def scene(self, i: int) -> Scene:
        mech, m, u = self.mech, self.motion, self.unit
        rows = slice(i, i + 1)
        sc = Scene()
        for name, local in mech.links[mech.frame].points.items():
            sc.points[name] = np.asarray(local, dtype=float)
        for link in mech.moving_links:
            if link not in m.poses:
                continue
            for name, local in mech.links[link].points.items():
                sc.points.setdefault(name, _global(m, link, local, rows)[0])
        pair_points, pivots, barrels = set(), [], set()
        for pair in mech.pairs.values():
            if isinstance(pair, Prismatic):
                glink, slider = pair.links
                if slider not in m.poses:
                    continue
                guide = mech.links[glink].guides[pair.guide]
                pose = np.zeros((1, 3)) if glink == mech.frame else m.poses[glink][rows]
                angle = float(pose[0, 2] + guide.angle)
                centre = _global(m, slider, mech.links[slider].points[pair.point], rows)[0]
                if pair.name in mech.inputs and glink != mech.frame:
                    sc.cylinders.append(self._cylinder(pair, pose, centre))
                    barrels.add((glink, pair.guide))
                else:
                    sc.blocks.append((slider, centre, angle, glink == mech.frame))
                pair_points.add(pair.point)
            else:
                p = sc.points.get(pair.point)
                if p is None:
                    continue
                sc.pins.append((pair.name, p))
                pair_points.add(pair.point)
                if mech.frame in pair.links:
                    pivots.append(p)
        # guides: the sliders' travel plus a block's length at each end
        for (glink, gname), (lo, hi) in self.travel.items():
            if (glink, gname) in barrels:
                continue
            guide = mech.links[glink].guides[gname]
            pose = np.zeros((1, 3)) if glink == mech.frame else m.poses[glink][rows]
            c, s = math.cos(pose[0, 2]), math.sin(pose[0, 2])
            rot = np.array([[c, -s], [s, c]])
            start = pose[0, :2] + rot @ np.asarray(guide.point, dtype=float)
            direction = rot @ np.array(guide.direction)
            pad = 1.9 * u if glink == mech.frame else 1.3 * u
            line = np.array([start + (lo - pad) * direction, start + (hi + pad) * direction])
            if glink == mech.frame:
                sc.rails.append((line, self._hatch_side(line, direction)))
            else:
                sc.slots.append((glink, line))
        for link in mech.moving_links:
            if link not in m.poses:
                continue
            pts = np.array([_global(m, link, local, rows)[0] for local in mech.links[link].points.values()])
            if len(pts) >= 2:
                sc.bodies.append((link, convex_hull(pts)))
        sc.dots = [n for n in sc.points if n not in pair_points]
        for name in self.trajectories:
            sc.trajectories.append((name, mech.point_link(name), self._sweep_points(name)))
        samples = scene_samples(sc, u)
        sc.pivots = [(p, _pivot_direction(p, sc, u, samples)) for p in pivots]
        return sc

    def _cylinder(self, pair, pose: np.ndarray, end: np.ndarray):
        """A cylinder drawn as a barrel and a rod that stay joined over the stroke: the barrel
        from its pivot end (or behind it, for a stroke longer than the shortest extension) to a
        gland 1.2 unit short of the rod end's nearest place; the rod, one length, from its end
        into the barrel, its piston 1.2 unit inside the gland at the longest extension."""
        barrel, rod = pair.links
        guide = self.mech.links[barrel].guides[pair.guide]
        lo, hi = self.travel[(barrel, pair.guide)]
        c, s = math.cos(pose[0, 2]), math.sin(pose[0, 2])
        rot = np.array([[c, -s], [s, c]])
        start = pose[0, :2] + rot @ np.asarray(guide.point, dtype=float)
        direction = rot @ np.array(guide.direction)
        u = self.unit
        front = max(lo - 1.2 * u, 0.5 * lo)
        rod_length = hi - front + 1.2 * u
        back = min(0.0, lo - rod_length - 1.2 * u)
        piston = end - rod_length * direction
        across = 0.55 * u * np.array([-direction[1], direction[0]])
        tube = _rect(start + (back + front) / 2 * direction, math.atan2(direction[1], direction[0]),
                     front - back, 1.4 * u)
        return barrel, rod, tube, np.array([piston, end]), np.array([piston - across, piston + across])

    def _hatch_side(self, line: np.ndarray, direction: np.ndarray) -> np.ndarray:
        """The side of a frame guide with fewer of the mechanism's points over a turn."""
        normal = np.array([-direction[1], direction[0]])
        pts = [self._sweep_points(n) for n in self.mech.point_names if self.mech.point_link(n) in self.sweep.poses]
        allp = np.vstack(pts)
        side = (allp - line[0]) @ normal
        side = side[np.isfinite(side) & (np.abs(side) > 1e-9 * self.span)]
        above, below = np.sum(side > 0), np.sum(side < 0)
        if above < below:
            return normal
        if below < above:
            return -normal
        return -normal if normal[1] > 0 or (normal[1] == 0 and normal[0] > 0) else normal


def _rect(centre: np.ndarray, angle: float, length: float, height: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    along, across = np.array([c, s]), np.array([-s, c])
    return np.array([centre + a * length / 2 * along + b * height / 2 * across
                     for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def support(p: np.ndarray, direction: float, u: float):
    """A frame pivot's support towards ``direction`` (rad): triangle, base and hatching."""
    d = np.array([math.cos(direction), math.sin(direction)])
    n = np.array([-d[1], d[0]])
    base = p + 1.9 * u * d
    triangle = np.array([p, base + 0.95 * u * n, base - 0.95 * u * n])
    ground = np.array([base + 1.5 * u * n, base - 1.5 * u * n])
    strokes = [(base + t * u * n, base + t * u * n + 0.7 * u * (d - n)) for t in np.linspace(-1.5, 1.5, 6)]
    return triangle, ground, np.array(strokes)


def rail_hatch(line: np.ndarray, side: np.ndarray, u: float):
    """The surface line of a frame guide at half a block's height on ``side``, and its hatching."""
    offset = 0.7 * u * side
    surface = line + offset
    direction = (line[1] - line[0]) / np.linalg.norm(line[1] - line[0])
    length = np.linalg.norm(line[1] - line[0])
    ts = np.arange(0.35 * u, length, 0.9 * u)
    strokes = np.array([(surface[0] + t * direction, surface[0] + t * direction + 0.7 * u * (side - direction))
                        for t in ts])
    return surface, strokes


def scene_samples(sc: Scene, u: float) -> np.ndarray:
    """Points along everything drawn at a scene except the supports, spaced u/3."""
    lines = [poly if len(poly) < 3 else np.vstack([poly, poly[:1]]) for _, poly in sc.bodies]
    lines += [line for _, line in sc.slots]
    for line, side in sc.rails:
        lines += [line, rail_hatch(line, side, u)[0]]
    lines += [np.vstack([r := _rect(c, a, *_block_size(u, f)), r[:1]]) for _, c, a, f in sc.blocks]
    lines += [curve for _, _, curve in sc.trajectories]
    lines += [item for _, _, tube, rod, _ in sc.cylinders for item in (np.vstack([tube, tube[:1]]), rod)]
    out = []
    for pts in lines:
        for a, b in zip(pts[:-1], pts[1:]):
            k = max(2, int(np.hypot(*(b - a)) / (u / 3)) + 1)
            out.append(a + np.linspace(0.0, 1.0, k)[:, None] * (b - a))
    out = np.vstack(out) if out else np.zeros((0, 2))
    return out[np.all(np.isfinite(out), axis=1)]


#: directions of a frame pivot's support, deg, in order of preference: down, then a wall on
#: either side, then up, then the diagonals
SUPPORT_DIRECTIONS = (-90, 180, 0, 90, -135, -45, 135, 45, -112.5, -67.5, -157.5, -22.5, 157.5, 22.5, 112.5,
                       67.5)


def _pivot_direction(p: np.ndarray, sc: Scene, u: float, samples: np.ndarray | None = None) -> float:
    """Direction (rad) of a pivot's support: the first of :data:`SUPPORT_DIRECTIONS` (down
    first) whose triangle, base and hatching cover the fewest points of the links, guides, blocks
    and trajectories."""
    samples = scene_samples(sc, u) if samples is None else samples
    samples = samples[np.hypot(*(samples - p).T) > 0.5 * u]
    best, best_cost = -math.pi / 2, math.inf
    for rank, deg in enumerate(SUPPORT_DIRECTIONS):
        a = math.radians(deg)
        tri, ground, strokes = support(p, a, u)
        region = convex_hull(np.vstack([tri, ground, strokes.reshape(-1, 2)]))
        covered = int(np.sum(points_inside(region, samples[np.hypot(*(samples - p).T) < 3.5 * u])))
        cost = covered + 0.1 * rank
        if cost < best_cost:
            best, best_cost = a, cost
    return best


def drawing_limits(sc_list: Sequence[Scene], geometry: Geometry) -> tuple[float, float, float, float]:
    """Axis limits holding everything drawn at every scene, with room for the labels."""
    u = geometry.unit
    pts = []
    for sc in sc_list:
        pts += list(sc.points.values())
        for _, poly in sc.bodies:
            pts += list(poly)
        for _, line in sc.slots:
            pts += list(line)
        for line, side in sc.rails:
            surface, strokes = rail_hatch(line, side, u)
            pts += list(line) + list(surface) + list(strokes.reshape(-1, 2))
        for _, centre, angle, on_frame in sc.blocks:
            pts += list(_rect(centre, angle, *_block_size(u, on_frame)))
        for p, direction in sc.pivots:
            tri, ground, strokes = support(p, direction, u)
            pts += list(tri) + list(ground) + list(strokes.reshape(-1, 2))
        for _, _, curve in sc.trajectories:
            pts += list(curve)
        for _, _, tube, rod, _ in sc.cylinders:
            pts += list(tube) + list(rod)
    pts = np.array(pts, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = max(float(max(hi - lo)), geometry.span)
    margin = 0.09 * span
    return lo[0] - margin, hi[0] + margin, lo[1] - margin, hi[1] + margin


def _block_size(u: float, on_frame: bool) -> tuple[float, float]:
    return (3.0 * u, 1.4 * u) if on_frame else (2.0 * u, 1.1 * u)


def figure_for(limits, panels: int = 1, ncols: int = 1, caption_lines: int = 2, header_lines: int = 0,
                text_chars: int = 0):
    """A figure and its axes rectangles, sized to the drawing's aspect: the width of an A4 page's
    text, or for one narrow drawing just wide enough for it and for ``text_chars`` characters of
    its caption."""
    x0, x1, y0, y1 = limits
    aspect = (y1 - y0) / (x1 - x0)
    nrows = math.ceil(panels / ncols)
    left, right, bottom = (0.8, 0.2, 0.6) if ncols == 1 else (0.7, 0.15, 0.55)
    top = 0.12 + 0.19 * caption_lines
    header = 0.1 + 0.22 * header_lines if header_lines else 0.0
    cell_w = PAGE_WIDTH / ncols
    width = cell_w - left - right
    height = width * aspect
    max_height = (9.2 - header) / nrows - bottom - top
    if height > max_height:
        height, width = max_height, max_height / aspect
    shift = (cell_w - left - right - width) / 2 if ncols > 1 else 0.0   # one drawing: flush left, under its caption
    cell_h = bottom + height + top
    fig_h = header + nrows * cell_h
    fig_w = PAGE_WIDTH
    if ncols == 1:
        fig_w = min(PAGE_WIDTH, max(left + width + right, left + text_chars * 0.6 * FONT / 72 + 0.25))
    fig = new_figure(fig_w, fig_h, layout=None)
    rects = []
    for k in range(panels):
        r, c = divmod(k, ncols)
        ax_left = c * cell_w + left + shift
        ax_bottom = fig_h - header - (r + 1) * cell_h + bottom
        rects.append((ax_left / fig_w, ax_bottom / fig_h, width / fig_w, height / fig_h))
    return fig, rects


def draw_mechanism(motion, position: int = 0, ax=None, *, labels: bool | Iterable[str] = True,
                   trajectories: Sequence[str] = (), limits: tuple[float, float, float, float] | None = None,
                   caption: bool | str = True):
    """Draw the mechanism to scale at one analysed position.

    Moving links are thick lines (two points) or filled polygons (three or more), revolute pairs
    circles, sliders blocks along their guides; guides of the frame are lines with hatching on
    the frame's side, guides of moving links (slots) lines in the link's colour; frame pivots
    stand on hatched supports. Point labels are placed away from the links, clear of every line,
    symbol and other label. The axes are in metres, equal aspect, and hold everything drawn.

    Parameters
    ----------
    motion : Motion
        Result of :func:`linkage.analyze`.
    position : int
        Index of the position in ``motion.phi`` (0 is position 1).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure sized to the drawing, the width of an A4 page's
        text). The labels are placed for the axes' size at the time of the call: set the figure's
        layout before drawing.
    labels : bool or iterable of str
        Write the names of all points (True), of none (False), or of these points.
    trajectories : sequence of str
        Points whose paths over a turn (over the input range) are drawn, dashed.
    limits : (xmin, xmax, ymin, ymax), optional
        Axis limits, m (default: everything drawn plus margins).
    caption : bool or str
        Title the drawing with the position number and the input angle in words (True), with the
        given text, or not at all (False).

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    InputError
        The position is not assembled; an unknown trajectory point.
    PlotExtraMissing
        matplotlib is not installed.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, numpy as np, linkage
    >>> mech = linkage.load("four_bar")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> ax = draw_mechanism(motion, 3, trajectories=["E"])
    >>> print(ax.get_title("left"))
    Position 4 of 12: the crank turned 90° counter-clockwise
    from position 1 (φ = 325.8° from the x axis)
    dashed: trajectory of E over a turn
    >>> ax.figure.savefig(io.BytesIO(), format="png")
    >>> ax.figure.savefig(io.BytesIO(), format="svg")
    >>> matplotlib.pyplot.close(ax.figure)
    """
    pyplot()
    i = _index(motion, position)
    geometry = Geometry(motion, [i], trajectories)
    sc = geometry.scene(i)
    limits = limits or drawing_limits([sc], geometry)
    text = position_caption(motion, i, trajectories) if caption is True else (caption or "")
    if ax is None:
        fig, rects = figure_for(limits, caption_lines=text.count("\n") + 1 if text else 0,
                                 text_chars=max((len(line) for line in text.splitlines()), default=0))
        ax = fig.add_axes(rects[0])
    draw_scene(ax, sc, geometry, limits, labels, text)
    return ax


def _index(motion, position: int) -> int:
    n = len(motion.phi)
    if not isinstance(position, (int, np.integer)) or not -n <= position < n:
        raise InputError(f"position must be an index of the {n} analysed angles, got {position!r}")
    return int(position) % n


def draw_positions(motion, positions: Sequence[int] | None = None, *, ncols: int | None = None,
                   labels: bool | Iterable[str] = True, trajectories: Sequence[str] = ()):
    """Draw the mechanism at several positions, side by side at one common scale.

    Parameters
    ----------
    motion : Motion
        Result of :func:`linkage.analyze` (e.g. at ``linkage.table_angles(mech, 12)``).
    positions : sequence of int, optional
        Indices into ``motion.phi`` (default: four positions evenly spread over the table).
    ncols : int, optional
        Panels per row (default: 2; 1 for a single position or a mechanism more than twice as
        wide as it is tall).
    labels, trajectories
        As in :func:`draw_mechanism`.

    Returns
    -------
    matplotlib Figure
        One axes per position, in the order given, each with its caption.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> mech = linkage.load("flying_shears")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> fig = draw_positions(motion, [0, 3, 6, 9], trajectories=["E"])
    >>> len(fig.axes)
    4
    >>> fig.savefig(io.BytesIO(), format="png")
    >>> matplotlib.pyplot.close(fig)
    """
    pyplot()
    n = len(motion.phi)
    if positions is None:
        last = n - 1 if n > 1 and abs(abs(motion.phi[-1] - motion.phi[0]) - 2 * np.pi) < 1e-9 else n
        positions = sorted({int(round(k * last / 4)) for k in range(4)}) if last >= 4 else list(range(last))
    idx = [_index(motion, p) for p in positions]
    if not idx:
        raise InputError("name at least one position to draw")
    geometry = Geometry(motion, idx, trajectories)
    scenes = [geometry.scene(i) for i in idx]
    limits = drawing_limits(scenes, geometry)
    aspect = (limits[3] - limits[2]) / (limits[1] - limits[0])
    if ncols is None:
        ncols = 1 if len(idx) == 1 or aspect < 0.45 else 2
    compact = ncols > 1
    texts = [position_caption(motion, i, compact=compact) for i in idx]
    lines = max(t.count("\n") + 1 for t in texts)
    who = input_word(motion.mechanism)
    what = (f"; φ: the {who}'s angle from the x axis" if motion.mechanism.coordinate.is_angle else
            f"; s: the {who}'s slide, m")
    header = [f"{motion.mechanism.name} at {len(idx)} positions, one scale" + (what if compact else "")]
    if trajectories:
        header.append(trajectory_note(motion.mechanism, trajectories))
    chars = max(len(line) for line in texts[0].splitlines() + header)
    fig, rects = figure_for(limits, len(idx), ncols, caption_lines=lines, header_lines=len(header),
                             text_chars=chars)
    if header:
        fig.suptitle("\n".join(header), fontsize=FONT, y=1 - 0.08 / fig.get_figheight(), va="top")
    for rect, sc, text in zip(rects, scenes, texts):
        ax = fig.add_axes(rect)
        draw_scene(ax, sc, geometry, limits, labels, text, font=FONT if ncols == 1 else SMALL, centred=True)
    return fig


def draw_scene(ax, sc: Scene, geometry: Geometry, limits, labels, caption: str, font: int = FONT,
                centred: bool = False) -> None:
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon

    mech, u = geometry.mech, geometry.unit
    colour = {link: LINK_COLOURS[k % len(LINK_COLOURS)] for k, link in enumerate(mech.moving_links)}
    # trajectories, under everything
    for name, link, curve in sc.trajectories:
        ax.plot(curve[:, 0], curve[:, 1], ls=(0, (5, 3)), lw=1.2, color=colour.get(link, "0.3"), zorder=1,
                gid=f"trajectory:{name}")
    # frame guides: centre line, surface and hatching
    for line, side in sc.rails:
        surface, strokes = rail_hatch(line, side, u)
        ax.plot(line[:, 0], line[:, 1], color="0.35", lw=0.8, ls=(0, (8, 3, 2, 3)), zorder=2, gid="guide")
        ax.plot(surface[:, 0], surface[:, 1], color="black", lw=1.4, zorder=2, gid="guide-surface")
        ax.add_collection(LineCollection(strokes, colors="black", linewidths=0.8, zorder=2, gid="hatching"))
    # frame pivots' supports
    for p, direction in sc.pivots:
        tri, ground, strokes = support(p, direction, u)
        ax.add_patch(Polygon(tri, closed=True, fc="white", ec="black", lw=1.2, zorder=3, gid="support"))
        ax.plot(ground[:, 0], ground[:, 1], color="black", lw=1.4, zorder=3, gid="support-base")
        ax.add_collection(LineCollection(strokes, colors="black", linewidths=0.8, zorder=3, gid="hatching"))
    # links, slots, sliders and blocks, pairs and points
    add_artists(ax, moving_artists(sc, geometry))
    x0, x1, y0, y1 = limits
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x, m", fontsize=font)
    ax.set_ylabel("y, m", fontsize=font)
    ax.tick_params(labelsize=SMALL if font >= FONT else SMALL - 1)
    _metre_ticks(ax)
    ax.grid(True, alpha=0.25, lw=0.6)
    ax.set_axisbelow(True)
    if caption:
        ax.set_title(caption, fontsize=font, loc="center" if centred else "left")
    if labels:
        wanted = list(sc.points) if labels is True else [n for n in labels if n in sc.points]
        place_point_labels(ax, sc, wanted, scene_obstacles(sc, u), font, PIN * u)


#: radius of a revolute pair's circle and of a point's dot, in the drawing's unit (a tenth of
#: the mechanism's size: :attr:`Geometry.unit`)
PIN = 0.42
DOT = 0.22


def scene_obstacles(sc: Scene, u: float, base: Drawn | None = None, trajectory_step: int = 1) -> Drawn:
    """What the labels of a scene must keep clear of (added to a copy of ``base``): every line,
    area and disc drawn; trajectories at every ``trajectory_step``-th point (light obstacles: a
    film searches its labels' places quicker on fewer segments)."""
    drawn = Drawn()
    if base is not None:
        drawn.segments, drawn.light = list(base.segments), list(base.light)
        drawn.discs, drawn.areas = list(base.discs), list(base.areas)
    for _, _, curve in sc.trajectories:
        drawn.polyline(np.vstack([curve[::trajectory_step], curve[-1:]]), light=True)
    for line, side in sc.rails:
        surface, strokes = rail_hatch(line, side, u)
        for polyline in (line, surface, *strokes):
            drawn.polyline(polyline)
    for p, direction in sc.pivots:
        tri, ground, strokes = support(p, direction, u)
        drawn.polyline(tri, closed=True)
        for polyline in (ground, *strokes):
            drawn.polyline(polyline)
    for _, poly in sc.bodies:
        drawn.polyline(poly, closed=len(poly) >= 3)
        if len(poly) >= 3:
            drawn.areas.append(poly)
    for _, line in sc.slots:
        drawn.polyline(line)
    for _, centre, angle, on_frame in sc.blocks:
        rect = _rect(centre, angle, *_block_size(u, on_frame))
        drawn.polyline(rect, closed=True)
        drawn.areas.append(rect)
    for _, _, tube, rod, _ in sc.cylinders:
        drawn.polyline(tube, closed=True)
        drawn.areas.append(tube)
        drawn.polyline(rod)
    drawn.discs += [(p, PIN * u) for _, p in sc.pins] + [(sc.points[n], DOT * u) for n in sc.dots]
    return drawn


def moving_artists(sc: Scene, geometry: Geometry) -> list:
    """The artists of a scene's moving parts: links, slots, sliders and blocks, pairs and points
    (colours, widths, layers and ids shared by the drawings and the film; add them with
    :func:`add_artists`)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Polygon

    mech, u = geometry.mech, geometry.unit
    colour = {link: LINK_COLOURS[k % len(LINK_COLOURS)] for k, link in enumerate(mech.moving_links)}
    colour[mech.frame] = "0.3"          # a block fixed to the frame, sliding in a moving link's guide
    out = []
    for link, poly in sc.bodies:
        c = colour[link]
        if len(poly) >= 3:
            out.append(Polygon(poly, closed=True, fc=c, alpha=0.18, ec="none", zorder=4, gid=f"link:{link}"))
            out.append(Polygon(poly, closed=True, fill=False, ec=c, lw=3.0, joinstyle="round", zorder=5,
                               gid=f"link-edge:{link}"))
        else:
            out.append(Line2D(poly[:, 0], poly[:, 1], color=c, lw=3.5, solid_capstyle="round", zorder=5,
                              gid=f"link:{link}"))
    for link, line in sc.slots:
        out.append(Line2D(line[:, 0], line[:, 1], color=colour[link], lw=5.0, solid_capstyle="butt", zorder=5,
                          gid=f"slot:{link}"))
        out.append(Line2D(line[:, 0], line[:, 1], color="white", lw=1.4, solid_capstyle="butt", zorder=5.1))
    for link, centre, angle, on_frame in sc.blocks:
        rect = _rect(centre, angle, *_block_size(u, on_frame))
        out.append(Polygon(rect, closed=True, fc="white", ec=colour[link], lw=2.2, zorder=6.5 if on_frame else 7,
                           gid=f"block:{link}"))
        out.append(Polygon(rect, closed=True, fc=colour[link], alpha=0.25, ec="none",
                           zorder=6.6 if on_frame else 7.1))
    for barrel, rod, tube, line, piston in sc.cylinders:
        out.append(Polygon(tube, closed=True, fc=colour[barrel], alpha=0.18, ec="none", zorder=6))
        out.append(Polygon(tube, closed=True, fill=False, ec=colour[barrel], lw=2.2, zorder=6.1,
                           gid=f"barrel:{barrel}"))
        out.append(Line2D(line[:, 0], line[:, 1], color=colour[rod], lw=3.0, solid_capstyle="butt", zorder=6.3,
                          gid=f"rod:{rod}"))
        out.append(Line2D(piston[:, 0], piston[:, 1], color=colour[rod], lw=3.0, solid_capstyle="butt", zorder=6.3,
                          gid=f"piston:{rod}"))
    for name, p in sc.pins:
        out.append(Circle(p, PIN * u, fc="white", ec="black", lw=1.4, zorder=8, gid=f"pair:{name}"))
    for name in sc.dots:
        out.append(Circle(sc.points[name], DOT * u, fc="black", ec="none", zorder=8, gid=f"point:{name}"))
    return out


def add_artists(ax, artists: list) -> list:
    """Add lines, patches and collections to ``ax`` (each where matplotlib keeps its kind)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    for artist in artists:
        if isinstance(artist, Line2D):
            ax.add_line(artist)
        elif isinstance(artist, Patch):
            ax.add_patch(artist)
        else:
            ax.add_collection(artist)
    return artists


def _metre_ticks(ax) -> None:
    """Ticks of a drawing: about one per 0.55 inch, none at the very edges of the axes (where their
    labels would run into the other axis's, or into the caption)."""
    from matplotlib.ticker import MaxNLocator

    ax.apply_aspect()
    box = ax.get_position()
    fig = ax.figure
    for axis, (lo, hi), inches in ((ax.xaxis, ax.get_xlim(), box.width * fig.get_figwidth()),
                                   (ax.yaxis, ax.get_ylim(), box.height * fig.get_figheight())):
        locator = MaxNLocator(nbins=max(3, int(inches / 0.55)), steps=[1, 2, 5, 10])
        edge = 0.03 * (hi - lo)
        ticks = [t for t in locator.tick_values(lo, hi) if lo + edge < t < hi - edge]
        axis.set_ticks(ticks)


# ----------------------------------------------------------------------------------------------
# labels of the points, where they collide with nothing
# ----------------------------------------------------------------------------------------------


def place_point_labels(ax, sc: Scene, names: Sequence[str], drawn: Drawn, font: int, pin_radius: float, *,
                       ranked: bool = False, drop: float = math.inf) -> list[str]:
    """Write the point names where they cover no line, symbol or other label, inside the axes.

    Works in display coordinates: each label tries 24 directions at three distances from its
    point and takes the candidate of least penalty (:func:`~linkage.report.labels.place_labels`):
    outside the axes, on another label, on a pair's circle, on a line (by the length covered),
    inside a link or block, far from its point or from the direction away from its links.
    Deterministic. Pairs' points are placed first (the most crowded), or with ``ranked`` the
    names in the order given; a label whose best place costs ``drop`` or more (1e4: it would
    overlap a label placed before) is left out. Returns the names written.
    """
    fig = ax.figure
    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()
    to_px = ax.transData.transform
    scale = fig.dpi / 72.0
    frame = ax.get_window_extent(renderer)
    inner = (frame.x0 + 2, frame.y0 + 2, frame.x1 - 2, frame.y1 - 2)
    px_per_m = abs(to_px(np.array([[1.0, 0.0]]))[0, 0] - to_px(np.array([[0.0, 0.0]]))[0, 0])

    def px(segs):
        segs = [x for x in segs if len(x)]
        if not segs:
            return np.zeros((0, 4))
        s = np.vstack(segs)
        return np.hstack([to_px(s[:, :2]), to_px(s[:, 2:])])

    on_screen = Drawn()         # the obstacles in pixels, a pixel to spare around the discs
    on_screen.segments, on_screen.light = [px(drawn.segments)], [px(drawn.light)]
    on_screen.discs = [(to_px(c[None])[0], r * px_per_m + 1) for c, r in drawn.discs]
    on_screen.areas = [to_px(a) for a in drawn.areas]
    r_pin = pin_radius * px_per_m
    centre_all = np.mean(np.array(list(sc.points.values())), axis=0)
    pin_points = _pin_points(sc)
    order = list(names) if ranked else sorted(names, key=lambda n: (n not in pin_points, n))  # pairs first
    steps = 2 * np.pi * np.arange(24) / 24
    ring = np.repeat(np.arange(3), len(steps))
    labels = []
    for name in order:
        p = sc.points[name]
        away = _away(sc, name, p, centre_all)
        text = ax.annotate(name, p, xytext=(0, 0), textcoords="offset points", ha="center", va="center",
                           fontsize=font, zorder=12, annotation_clip=False, gid=f"label:{name}",
                           bbox=dict(boxstyle="square,pad=0.08", fc="white", ec="none", alpha=0.75))
        angle = away + np.tile(steps, 3)
        deviation = np.abs((angle - away + np.pi) % (2 * np.pi) - np.pi)
        labels.append(Label(text, to_px(p[None])[0], np.stack([np.cos(angle), np.sin(angle)], axis=1),
                            r_pin + 3 + 5 * scale * ring, 40.0 * ring + 15.0 * deviation, drop))
    written = []
    for name, label, place in zip(order, labels, place_labels(labels, on_screen, inner, renderer)):
        if place is not None:
            offset = place.centre - label.anchor
            label.text.set_position((offset[0] / scale, offset[1] / scale))
            written.append(name)
    return written


def _pin_points(sc: Scene) -> set[str]:
    return {name for name, p in sc.points.items() if any(np.allclose(p, q) for _, q in sc.pins)}


def _away(sc: Scene, name: str, p: np.ndarray, centre_all: np.ndarray) -> float:
    """The direction (rad) away from the links at a point: from the mean of the directions to the
    other points of the bodies through it (else from the drawing's centre)."""
    dirs = []
    for _, poly in sc.bodies:
        if np.min(np.hypot(*(poly - p).T)) < 1e-9 * (1 + np.max(np.abs(poly))):
            for q in poly:
                v = q - p
                n = np.hypot(*v)
                if n > 0:
                    dirs.append(v / n)
    if dirs:
        mean = np.mean(dirs, axis=0)
        if np.hypot(*mean) > 1e-6:
            return math.atan2(-mean[1], -mean[0])
        v = dirs[0]
        return math.atan2(v[0], -v[1])  # along a straight link: to its side
    v = p - centre_all
    return math.atan2(v[1], v[0]) if np.hypot(*v) > 0 else math.pi / 2
