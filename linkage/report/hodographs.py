"""Hodographs of the pair reactions: the locus of the tip of each reaction vector over the cycle.

The reaction of a pair K declared with ``links = [a, b]`` is ``R[a, b]``, the force that link b
exerts on link a (docs/conventions.md): the vector whose components are the columns ``K.Rx`` and
``K.Ry`` of the forces table (``linkage forces``, ``Reactions.columns(full=True)``); for a
prismatic pair the force normal to the guide (its moment is not drawn). Every vector is drawn
from one origin; the curve its tip runs along over the cycle is the hodograph, with the table
positions marked and numbered along it.

- :func:`main_pairs` -- the pairs a course work draws: those of the input link and those joining
  a moving link to the frame;
- :func:`plot_hodographs` -- one panel per pair, equal scales on both axes, N.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import linkage
>>> main_pairs(linkage.load("slider_crank"))
['O', 'A', 'slide']
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import pairwise

import numpy as np

from ..errors import InputError
from ..model.mechanism import Mechanism
from .drawing import Scene, place_point_labels
from .labels import Drawn
from .style import CURVE_COLOURS, FONT, PAGE_WIDTH, SMALL, fit_width, new_figure, pyplot
from .words import link_role, speed_words, table_span

__all__ = ["main_pairs", "pair_words", "plot_hodographs"]

#: height of a row of panels, inches
PANEL_HEIGHT = 3.1
#: a reaction is drawn as missing (zero) when its largest magnitude is at most this fraction of
#: the largest reaction in the mechanism (0 when every reaction is 0)
ZERO = 1e-12


def main_pairs(mechanism: Mechanism) -> list[str]:
    """The pairs whose reactions a course work draws: the input link's pairs (its frame
    bearing first), then the other pairs that join a moving link to the frame (bearings of
    rockers, guides of sliders), each in the order the scheme declares them.

    Parameters
    ----------
    mechanism : Mechanism

    Returns
    -------
    list of str
        Pair names.

    Examples
    --------
    >>> import linkage
    >>> main_pairs(linkage.load("four_bar"))
    ['O', 'A', 'C']
    >>> main_pairs(linkage.load("slotted_link_two_dyad"))
    ['O1', 'A', 'O3', 'ram']
    """
    mech = mechanism
    pairs = list(mech.pairs.values())
    # the input links; a cylinder (an input that is a pair between two moving links) brings both
    # of its links, barrel and rod: its own pair and theirs are its "input pairs"
    inputs: set[str] = set()
    for name in mech.inputs:
        inputs |= set(mech.pairs[name].links) - {mech.frame} if name in mech.pairs else {name}
    on_frame = [p.name for p in pairs if mech.frame in p.links]
    of_input = [p.name for p in pairs if set(p.links) & inputs]
    ordered = [n for n in of_input if n in on_frame] + [n for n in of_input if n not in on_frame] + on_frame
    return list(dict.fromkeys(ordered))


def pair_words(mechanism: Mechanism, pair: str) -> str:
    """The reaction of a pair in words, as the hodographs and the forces table give it: the
    force of the pair's second link on its first, by their roles.

    >>> import linkage
    >>> pair_words(linkage.load("four_bar"), "O")
    'pair O: force of crank 1 on frame 0'
    """
    a, b = mechanism.pairs[pair].links
    return f"pair {pair}: force of {link_role(mechanism, b)} {b} on {link_role(mechanism, a)} {a}"


def _chosen_pairs(reactions, pairs: Sequence[str] | None) -> list[str]:
    mech = reactions.motion.mechanism
    if isinstance(pairs, str):
        raise InputError(f"pairs must be a list of pair names, got the string {pairs!r}")
    names = main_pairs(mech) if pairs is None else list(pairs)
    if not names:
        raise InputError("name at least one pair to draw the hodograph of")
    unknown = [n for n in names if n not in reactions.multipliers]
    if unknown:
        raise InputError(f"no reaction of pair {unknown[0]!r} in mechanism '{mech.name}'; its pairs: "
                         f"{sorted(reactions.multipliers)}")
    return list(dict.fromkeys(names))


def _numbers(points: np.ndarray, numbers: np.ndarray, span: float, closed: bool) -> dict[str, np.ndarray]:
    """Label text -> point, in the order the labels are placed (a label with no room is left
    out): position 1, then every :data:`COARSE`-th, then the others. Table positions whose
    vectors coincide (to 1e-9 of the drawing's span) share one label, ``"3, 9"``; over a turn
    (``closed``) the last row is position 1 again and carries no number of its own."""
    labels: dict[str, np.ndarray] = {}
    count = len(points) - 1 if closed else len(points)
    ok = np.all(np.isfinite(points), axis=1)
    ok[count:] = False
    taken = ~ok
    rank = np.arange(count)
    order = sorted(rank, key=lambda k: (k != 0, k % COARSE != 0, k))
    for k in order:
        if taken[k]:
            continue
        same = ~taken & (np.hypot(*(points - points[k]).T) <= 1e-9 * span)
        taken |= same
        labels[", ".join(str(int(n)) for n in numbers[same])] = points[k]
    return labels


#: every COARSE-th table position is numbered before the others
COARSE = 6


def plot_hodographs(reactions, pairs: Sequence[str] | None = None, *, fine=None):
    """Hodographs of pair reactions: one panel per pair, the vectors ``R`` of every table
    position drawn from one origin and the curve their tip runs along.

    Each panel shows, for a pair K declared with ``links = [a, b]``, the force ``R[a, b]`` that
    link b exerts on link a (the forces table's ``K.Rx``, ``K.Ry``), N, with equal scales on both
    axes: the table positions as circles numbered along the curve where a number has room (1,
    then every 6th, then the others; positions that coincide share a label, and over a turn row
    n+1, position 1 again, has none), thin lines from the origin to them (the vectors), and
    the axes through the origin. A pair whose reaction is zero at every position (no masses,
    loads or inertia forces reach it) gets a note instead of an empty panel.

    Parameters
    ----------
    reactions : Reactions
        :func:`linkage.kinetostatics.reactions.solve_reactions` at the table positions (e.g. as ``linkage
        forces`` makes them: the scheme's table, at its speed).
    pairs : sequence of str, optional
        The pairs to draw, in this order (default: :func:`main_pairs`).
    fine : Reactions, optional
        The same reactions on a finer grid of angles over the same cycle: drawn as the curve,
        the table positions marked on it. Without it the curve joins the table positions.

    Returns
    -------
    matplotlib Figure
        The axes of the panels in the order of the pairs; each curve's line has the id
        ``"hodograph:K"`` and the table positions' ``"positions:K"``.

    Raises
    ------
    InputError
        An unknown pair, an empty list of pairs.
    PlotExtraMissing
        matplotlib is not installed.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> from linkage.kinetostatics.reactions import solve_reactions
    >>> mech = linkage.load("four_bar")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12), omega=10.0)
    >>> fig = plot_hodographs(solve_reactions(motion))
    >>> [ax.get_title(loc="left").replace("\\n", " ") for ax in fig.axes[:3]]
    ['pair O: force of crank 1 on frame 0', 'pair A: force of coupler 2 on crank 1', 'pair C: force of frame 0 on rocker 3']
    >>> fig.savefig(io.BytesIO(), format="png")
    >>> matplotlib.pyplot.close(fig)
    """
    pyplot()
    names = _chosen_pairs(reactions, pairs)
    mech = reactions.motion.mechanism
    largest = max((float(np.nanmax(np.abs(reactions.force(n)), initial=0.0)) for n in reactions.multipliers),
                  default=0.0)
    ncols = 1 if len(names) == 1 else 2
    nrows = math.ceil(len(names) / ncols)
    fig = new_figure(PAGE_WIDTH, min(9.5, 0.75 + PANEL_HEIGHT * nrows))
    grid = fig.subplots(nrows, ncols, squeeze=False).ravel()
    numbers = np.arange(1, len(reactions.motion.phi) + 1)
    fit_width(fig.suptitle(_header(reactions), fontsize=FONT))
    distinct = numbers[:-1] if table_span(reactions.motion).endswith(" = 1)") else numbers
    for ax in grid[len(names):]:              # an empty cell: how to read the panels
        _key(ax, distinct, fine is not None)
    placed = []
    for k, (ax, name) in enumerate(zip(grid, names)):
        force = reactions.force(name)
        finite = np.all(np.isfinite(force), axis=1)
        ax.set_title(pair_words(mech, name).replace(": ", ":\n", 1), fontsize=FONT, loc="left")
        size = float(np.max(np.abs(force[finite]), initial=0.0))
        if not finite.any() or size == 0.0 or size <= ZERO * largest:
            _missing(ax, name, finite.any())
            continue
        curve = fine.force(name) if fine is not None and name in fine.multipliers else force
        placed.append(_panel(ax, name, force, curve, CURVE_COLOURS[k % len(CURVE_COLOURS)]))
    fig.canvas.draw()                      # constrained layout places the panels once ...
    fig.set_layout_engine("none")          # ... and keeps them, so that the numbers stay where placed
    closed = table_span(reactions.motion).endswith(" = 1)")
    for ax, name, force in placed:
        _equal_scales(ax)
        _thin_ticks(ax)
        _number(ax, force, numbers, closed)
    return fig


def _header(reactions) -> str:
    mech = reactions.motion.mechanism
    return (f"Hodographs of the pair reactions of {mech.name},\n{speed_words(reactions.motion)};\n"
            f"vectors R from the origin (+) at the {table_span(reactions.motion)}, numbered where there is room")


def _key(ax, numbers: np.ndarray, fine: bool) -> None:
    """How to read the panels, written in a cell the panels leave empty."""
    last = f"{int(numbers[0])} … {int(numbers[-1])}" if len(numbers) > 1 else f"{int(numbers[0])}"
    curve = "a fine grid of angles" if fine else "joining the table positions"
    lines = ["How to read a panel:",
             "+   the origin of the vectors R",
             "grey lines: R at the table",
             f"     positions {last}",
             "circles: their tips, numbered",
             "     where there is room",
             "curve: the tip of R over the cycle",
             f"     ({curve})",
             "R in a pair [a, b]: the force of",
             "     link b on link a, as the forces",
             "     table's columns K.Rx, K.Ry"]
    ax.axis("off")
    ax.text(0.06, 0.5, "\n".join(lines), transform=ax.transAxes, ha="left", va="center", fontsize=SMALL,
            linespacing=1.35, gid="key")


def _missing(ax, name: str, assembled: bool) -> None:
    """A note in place of an empty panel."""
    text = (f"no reaction in pair {name}:\nR = 0 at every position\n(no masses, loads or inertia\nforces reach it)"
            if assembled else f"pair {name} is not assembled\nat any position")
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=SMALL, gid=f"missing:{name}")
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_color("0.75")


def _panel(ax, name: str, force: np.ndarray, curve: np.ndarray, colour: str):
    """One hodograph: axes through the origin, the vectors, the curve, the table positions."""
    from matplotlib.collections import LineCollection
    from matplotlib.ticker import MaxNLocator

    ok = np.all(np.isfinite(force), axis=1)
    ax.axhline(0.0, color="0.45", lw=0.8, zorder=1)
    ax.axvline(0.0, color="0.45", lw=0.8, zorder=1)
    rays = [np.array([[0.0, 0.0], p]) for p in force[ok]]
    ax.add_collection(LineCollection(rays, colors="0.6", linewidths=0.7, zorder=2, gid=f"vectors:{name}"))
    ax.plot(curve[:, 0], curve[:, 1], "-", color=colour, lw=1.8, zorder=3, gid=f"hodograph:{name}")
    ax.plot(force[:, 0], force[:, 1], ls="none", marker="o", ms=_marker(len(force)), mfc="white", mec=colour, mew=1.4,
            zorder=4, gid=f"positions:{name}")
    ax.plot([0.0], [0.0], marker="+", ms=8, mew=1.4, color="black", zorder=5, gid="origin")
    ax.margins(0.12)                      # room for the numbers; the limits follow the data ...
    ax.set_aspect("equal", adjustable="datalim")   # ... widened to equal scales
    ax.set_xlabel("x component $R_x$, N", fontsize=FONT)
    ax.set_ylabel("y component $R_y$, N", fontsize=FONT)
    ax.tick_params(labelsize=SMALL)
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MaxNLocator(nbins=TICKS, steps=TICK_STEPS))
    ax.grid(True, alpha=0.3)
    return ax, name, force


#: size of the table positions' circles, points (smaller for more than :data:`NUMBERED`)
MARKER = 5.0
#: of more positions than this, the circles are drawn smaller
NUMBERED = 40


def _marker(count: int) -> float:
    return MARKER if count <= NUMBERED else 3.0
#: most intervals between the ticks of a panel's axis, and the steps they may take
TICKS = 6
TICK_STEPS = [1, 2, 2.5, 5, 10]


def _equal_scales(ax) -> None:
    """Widen one axis's limits (about their middle) so that a newton is exactly as long on both
    axes (matplotlib's own equal aspect leaves up to 0.5 % between them)."""
    ax.apply_aspect()
    box = ax.get_window_extent()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    per_x, per_y = box.width / (x1 - x0), box.height / (y1 - y0)     # pixels per newton
    if per_x > per_y:
        half = box.width / per_y / 2
        ax.set_xlim((x0 + x1) / 2 - half, (x0 + x1) / 2 + half)
    elif per_y > per_x:
        half = box.height / per_x / 2
        ax.set_ylim((y0 + y1) / 2 - half, (y0 + y1) / 2 + half)


def _thin_ticks(ax) -> None:
    """Fewer ticks on an axis whose tick labels run into each other (long numbers like
    ``−20000`` on a narrow panel): down to 2 intervals, until a space of half a label's height
    parts every two."""
    from matplotlib.ticker import MaxNLocator

    renderer = ax.figure.canvas.get_renderer()
    for axis, along in ((ax.xaxis, 0), (ax.yaxis, 1)):
        for nbins in range(TICKS, 1, -1):
            axis.set_major_locator(MaxNLocator(nbins=nbins, steps=TICK_STEPS))
            lo, hi = sorted(axis.get_view_interval())
            shown = [t for v, t in zip(axis.get_ticklocs(), axis.get_ticklabels()) if lo <= v <= hi and t.get_text()]
            boxes = [t.get_window_extent(renderer) for t in shown]
            spans = sorted((b.x0, b.x1) if along == 0 else (b.y0, b.y1) for b in boxes)
            gap = 0.5 * max((b.height for b in boxes), default=0.0)
            if all(lo2 - hi1 >= gap for (_, hi1), (lo2, _) in pairwise(spans)):
                break


def _number(ax, force: np.ndarray, numbers: np.ndarray, closed: bool) -> list[str]:
    """Number the table positions along the hodograph, where the numbers cover no line, circle
    or other number (:func:`~linkage.report.drawing.place_point_labels`, outward from the curve);
    a number with no room left is left out. Returns the labels written."""
    ax.apply_aspect()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    span = max(x1 - x0, y1 - y0)
    sc = Scene(points=_numbers(force, numbers, span, closed))
    px_per_unit = abs(ax.transData.transform([[1.0, 0.0]])[0, 0] - ax.transData.transform([[0.0, 0.0]])[0, 0])
    radius = (_marker(len(force)) / 2 + 0.7) * ax.figure.dpi / 72.0 / px_per_unit
    drawn = Drawn()
    for line in ax.get_lines():
        data = np.asarray(line.get_xydata(), dtype=float)
        if (line.get_gid() or "").startswith("hodograph:"):
            drawn.polyline(data)
    for p in sc.points.values():
        drawn.discs.append((p, radius))
    for coll in ax.collections:
        for seg in coll.get_segments():
            drawn.polyline(seg, light=True)
    drawn.polyline(np.array([[x0, 0.0], [x1, 0.0]]), light=True)
    drawn.polyline(np.array([[0.0, y0], [0.0, y1]]), light=True)
    return place_point_labels(ax, sc, list(sc.points), drawn, SMALL, radius, ranked=True, drop=1e4)
