"""Pictures of a mechanism and of its results (needs the ``plot`` extra: matplotlib).

>>> import numpy as np, linkage
>>> from linkage.report.plots import draw_mechanism
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> motion = linkage.analyze(linkage.load("slotted_link_two_dyad"), np.radians([30.0]))
>>> ax = draw_mechanism(motion, 0)
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from assur.base import global_point

from ..errors import InputError

__all__ = ["draw_mechanism", "plot_columns"]


def _axes(ax):
    if ax is not None:
        return ax
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise ImportError("plots need matplotlib: pip install 'linkage[plot]'") from exc
    return plt.figure().add_subplot()


def draw_mechanism(motion, position: int = 0, ax=None, *, labels: bool = True):
    """Draw the mechanism at one analysed position.

    Each moving link is drawn as the polygon of its points, revolute pairs as circles, sliders as
    squares, guide lines dashed, frame points as triangles.

    Parameters
    ----------
    motion : Motion
        Result of :func:`linkage.analyze`.
    position : int
        Index of the position in ``motion.phi``.
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure).
    labels : bool
        Write the point names.

    Returns
    -------
    matplotlib Axes
    """
    ax = _axes(ax)
    mech, i = motion.mechanism, position
    size = mech.size
    for name in mech.moving_links:
        link = mech.links[name]
        if name not in motion.poses or not link.points:
            continue
        pose = motion.poses[name][i : i + 1]
        pts = np.array([global_point(pose, p)[0] for p in link.points.values()])
        closed = np.vstack([pts, pts[:1]]) if len(pts) > 2 else pts
        ax.plot(closed[:, 0], closed[:, 1], "-", lw=3, alpha=0.8, label=f"link {name}")
        for guide in link.guides.values():
            _guide(ax, pose, guide, size)
    for guide in mech.links[mech.frame].guides.values():
        _guide(ax, np.zeros((1, 3)), guide, 2 * size)
    for pname, pair in mech.pairs.items():
        link = pair.links[1]
        if link not in motion.poses:
            continue
        p = global_point(motion.poses[link][i : i + 1], mech.links[link].points[pair.point])[0]
        marker = "o" if pair.kind == "R" else "s"
        ax.plot(*p, marker, ms=8, mfc="white", mec="black", zorder=3)
    frame_points = mech.links[mech.frame].points
    for p in frame_points.values():
        ax.plot(*p, "^", ms=10, color="gray", zorder=2)
    if labels:
        for pname in mech.point_names:
            link = mech.point_link(pname)
            if link in motion.poses:
                p = global_point(motion.poses[link][i : i + 1], mech.links[link].points[pname])[0]
                ax.annotate(pname, p, textcoords="offset points", xytext=(5, 5))
    ax.set_aspect("equal")
    ax.set_title(f"{mech.name}, phi = {np.degrees(motion.phi[i]):.1f} deg")
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    return ax


def _guide(ax, pose, guide, length):
    start = global_point(pose, guide.point)[0]
    direction = np.array([np.cos(pose[0, 2] + guide.angle), np.sin(pose[0, 2] + guide.angle)])
    ends = np.array([start - length * direction, start + length * direction])
    ax.plot(ends[:, 0], ends[:, 1], "--", color="gray", lw=1)


def plot_columns(columns: dict, names: Sequence[str], ax=None):
    """Plot table columns (e.g. ``Motion.columns()``) against ``phi_deg``."""
    ax = _axes(ax)
    phi = columns["phi_deg"]
    for name in names:
        if name not in columns:
            raise InputError(f"no column {name!r}; columns: {list(columns)}")
        values = np.asarray(columns[name], dtype=float)
        if name.endswith(".theta"):            # angles in (-pi, pi]: drawn as continuous curves
            values = _unwrap(values, 2 * np.pi)
        elif name.endswith("angle_deg"):
            values = _unwrap(values, 360.0)
        ax.plot(phi, values, label=name)
    ax.set_xlabel("phi, deg")
    ax.legend()
    ax.grid(True, alpha=0.3)
    return ax


def _unwrap(values: np.ndarray, period: float) -> np.ndarray:
    """Remove the jumps of a wrapped angle column (NaN rows kept as gaps)."""
    out = values.copy()
    ok = np.isfinite(values)
    out[ok] = np.unwrap(values[ok], period=period)
    return out
