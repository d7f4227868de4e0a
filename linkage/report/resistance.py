"""The useful resistance over the stroke, P(s): each external force against the travel of its point.

For every external force of a scheme's ``[loads]`` (gravity and inertia left out), ``s`` is the
travel of its point along the force's line of action at the force's largest magnitude, measured
from the point's nearest place to it over the cycle (m), and ``P`` the force's component along
that line (N): the diagram a course project draws of the press's, pump's or shears' useful
resistance. The curve is drawn over the cycle at 1° steps of the input (so a diagram's corners
between table positions are drawn), in the order of the cycle (working stroke and return); the
table positions are marked and numbered where there is room (a number that would sit on another
is left out).

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import linkage
>>> mech = linkage.load("course_slider_crank")
>>> fig = plot_resistance(linkage.analyze(mech, linkage.table_angles(mech, 12)))
>>> fig.axes[0].get_xlabel()
'travel s of B along the force, m'
>>> matplotlib.pyplot.close(fig)
"""

from __future__ import annotations

import numpy as np

from assur.base import global_point

from ..errors import InputError
from ..kinematics.motion import analyze
from ..kinetostatics.loads import evaluate_loads, loads_of
from .style import CURVE_COLOURS, FONT, SMALL, new_figure, pyplot
from .words import position_head

__all__ = ["resistance_curves", "plot_resistance"]


def resistance_curves(motion, frame: "list[tuple[np.ndarray, float]] | None" = None
                      ) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``(point, s, P)`` per external force: the travel ``s`` (m, from 0) of its point along
    the force's line and the force ``P`` along it (N), at the positions of ``motion``.

    ``frame``: per force, the line's direction ``(2,)`` and the travel's origin (m) to measure
    with (:func:`_lines` of another motion of the same mechanism), so that two sweeps share
    them; default: this motion's own."""
    lines = _lines(motion)
    out = []
    for (point, along, position, force), ref in zip(lines, frame or [None] * len(lines)):
        unit, origin = ref if ref is not None else (along, float(np.nanmin(position @ along)))
        out.append((point, position @ unit - origin, force @ unit))
    return out


def _lines(motion) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """``(point, along, position, force)`` per external force with a nonzero value: the unit
    direction of the force at its largest magnitude ``(2,)``, its point's positions ``(N, 2)``
    and the force ``(N, 2)``."""
    mech = motion.mechanism
    loads = loads_of(mech)
    out = []
    for term, spec in zip([t for t in evaluate_loads(motion, loads) if t.kind != "gravity"], loads.forces):
        force = np.asarray(term.force, dtype=float)
        size = np.hypot(*force.T)
        if not np.any(np.nan_to_num(size) > 0):
            continue
        k = int(np.nanargmax(size))
        out.append((spec.point, force[k] / size[k], global_point(motion.poses[term.link], term.local), force))
    return out


def plot_resistance(motion):
    """P(s): one panel per external force, N against m, the table positions numbered.

    Raises
    ------
    InputError
        The scheme declares no external force.
    """
    pyplot()
    phi = np.asarray(motion.phi, float)
    steps = max(2, int(np.ceil(abs(phi[-1] - phi[0]) / np.radians(1.0))) + 1)
    sweep = analyze(motion.mechanism, np.linspace(phi[0], phi[-1], steps), order=2, on_failure="mask")
    lines = [(along, float(np.nanmin(position @ along))) for _, along, position, _ in _lines(sweep)]
    dense = resistance_curves(sweep, lines)
    curves = resistance_curves(motion, lines)
    if not curves:
        raise InputError(f"scheme '{motion.mechanism.name}' declares no external force: no P(s) to draw")
    fig = new_figure(6.3, 3.2 * len(curves))
    axes = fig.subplots(len(curves), 1, squeeze=False).ravel()
    count = position_head(motion, 0).rpartition(" of ")[2]
    numbered = min(len(phi), int(count) if count.isdigit() else len(phi))
    for ax, (point, s, force), (_, s_dense, force_dense), colour in zip(axes, curves, dense, CURVE_COLOURS):
        ax.plot(s_dense, force_dense, "-", color=colour, lw=1.6, gid=f"resistance:{point}")
        ax.plot(s[:numbered], force[:numbered], "o", color=colour, mfc="white", ms=4)
        _number_where_there_is_room(fig, ax, s[:numbered], force[:numbered])
        ax.axhline(0.0, color="0.45", lw=0.8)
        ax.set_xlabel(f"travel s of {point} along the force, m", fontsize=FONT)
        ax.set_ylabel("force P along its line, N", fontsize=FONT)
        ax.set_title(f"Useful resistance P(s) at {point}: the force against the travel of its point",
                     fontsize=FONT, loc="left")
        ax.tick_params(labelsize=SMALL)
        ax.grid(True, alpha=0.3)
    return fig


def _number_where_there_is_room(fig, ax, s: np.ndarray, force: np.ndarray, room: float = 11.0) -> None:
    """Number the marked positions 1, 2 ..., leaving out a number whose anchor lies within
    ``room`` points (display) of one already numbered (position 1 first)."""
    ax.set_xlim(ax.get_xlim())
    ax.set_ylim(ax.get_ylim())
    at = ax.transData.transform(np.column_stack([s, force])) * 72.0 / fig.dpi
    kept: list[np.ndarray] = []
    for k in range(len(s)):
        if not np.all(np.isfinite(at[k])) or any(np.hypot(*(at[k] - q)) < room for q in kept):
            continue
        kept.append(at[k])
        ax.annotate(str(k + 1), (s[k], force[k]), xytext=(3, 4), textcoords="offset points", fontsize=SMALL - 1)
