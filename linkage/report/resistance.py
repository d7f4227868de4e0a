"""The useful resistance over the stroke, P(s): each external force against the travel of its point.

For every external force of a scheme's ``[loads]`` (gravity and inertia left out), ``s`` is the
travel of its point along the force's line of action at the force's largest magnitude, measured
from the point's nearest place to it over the cycle (m), and ``P`` the force's component along
that line (N): the diagram a course project draws of the press's, pump's or shears' useful
resistance. The table positions are marked and numbered; the curve runs through them in the
order of the cycle (working stroke and return).

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
from ..kinetostatics.loads import evaluate_loads, loads_of
from .style import CURVE_COLOURS, FONT, SMALL, new_figure, pyplot
from .words import position_head

__all__ = ["resistance_curves", "plot_resistance"]


def resistance_curves(motion) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``(point, s, P)`` per external force: the travel ``s`` (m, from 0) of its point along
    the force's line and the force ``P`` along it (N), at the positions of ``motion``."""
    mech = motion.mechanism
    loads = loads_of(mech)
    out = []
    for term, spec in zip([t for t in evaluate_loads(motion, loads) if t.kind != "gravity"], loads.forces):
        force = np.asarray(term.force, dtype=float)
        size = np.hypot(*force.T)
        if not np.any(np.nan_to_num(size) > 0):
            continue
        k = int(np.nanargmax(size))
        along = force[k] / size[k]
        point = global_point(motion.poses[term.link], term.local) @ along
        out.append((spec.point, point - np.nanmin(point), force @ along))
    return out


def plot_resistance(motion):
    """P(s): one panel per external force, N against m, the table positions numbered.

    Raises
    ------
    InputError
        The scheme declares no external force.
    """
    pyplot()
    curves = resistance_curves(motion)
    if not curves:
        raise InputError(f"scheme '{motion.mechanism.name}' declares no external force: no P(s) to draw")
    fig = new_figure(6.3, 3.2 * len(curves))
    axes = fig.subplots(len(curves), 1, squeeze=False).ravel()
    count = position_head(motion, 0).rpartition(" of ")[2]
    for ax, (point, s, force), colour in zip(axes, curves, CURVE_COLOURS):
        ax.plot(s, force, "-o", color=colour, mfc="white", ms=4, lw=1.6, gid=f"resistance:{point}")
        for k in range(min(len(s), int(count) if count.isdigit() else len(s))):
            ax.annotate(str(k + 1), (s[k], force[k]), xytext=(3, 4), textcoords="offset points", fontsize=SMALL - 1)
        ax.axhline(0.0, color="0.45", lw=0.8)
        ax.set_xlabel(f"travel s of {point} along the force, m", fontsize=FONT)
        ax.set_ylabel("force P along its line, N", fontsize=FONT)
        ax.set_title(f"Useful resistance P(s) at {point}: the force against the travel of its point",
                     fontsize=FONT, loc="left")
        ax.tick_params(labelsize=SMALL)
        ax.grid(True, alpha=0.3)
    return fig
