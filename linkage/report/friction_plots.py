"""The picture of friction in the pairs (docs/friction.md): where the power goes, and the efficiency.

:func:`plot_friction` draws, over the angle turned from position 1 in the direction of rotation
(``phi_deg``, as every table and diagram of the library), two panels:

(a) the power friction takes in each pair with friction, W (>= 0, one line per pair) and their
    total;
(b) the instantaneous efficiency ``η = −P_useful / P_driving``
    (:meth:`~linkage.kinetostatics.reactions.Reactions.efficiency`), left out where the drive
    delivers no power, and the cycle efficiency of one turn at constant speed
    (:func:`~linkage.kinetostatics.efficiency.cycle_works`) as a dashed line with its value.

The table positions are marked and numbered; the curves between them come from the same
analysis on a finer grid of angles (checked against the table: where it disagrees, the table's
positions are joined instead). Needs the ``plot`` extra (matplotlib).

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import linkage
>>> from linkage.report.results import forces_results
>>> reactions = forces_results(linkage.load("course_slider_crank"), friction=True).reactions
>>> fig = plot_friction(reactions)
>>> [ax.get_ylabel().replace("\\n", " ") for ax in fig.axes[:2]]
['power lost to friction $P_f$, W', 'efficiency $\\\\eta$ (dimensionless)']
>>> matplotlib.pyplot.close(fig)
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from assur.base import PrismaticJoint

from ..errors import InputError, LinkageError
from ..kinematics.motion import analyze, position_column, table_positions_deg
from ..kinetostatics.efficiency import CycleWorks, cycle_works
from ..kinetostatics.reactions import Reactions, solve_reactions
from .diagrams import _fine_angles, extreme_marks, number_positions, style_angle_axis, wrapped_label
from .style import CURVE_COLOURS, FONT, MARKERS, PAGE_WIDTH, SMALL, fit_width, new_figure, pyplot
from .words import describe_column, speed_words

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_friction", "friction_curves"]

#: relative agreement the fine grid's values must have with the table's at the table positions
AGREEMENT = 1e-6


def _positions(reactions: Reactions, direction: int | None) -> np.ndarray:
    """The table's x axis: ``phi_deg`` (deg turned from position 1), or ``s`` (m) for a slide input."""
    motion = reactions.motion
    if motion.mechanism.coordinate.is_angle:
        return table_positions_deg(motion.phi, motion.direction if direction is None else direction)
    return np.asarray(motion.phi, dtype=float).copy()


def _uniform(values) -> float | None:
    """The one value of a speed or acceleration array (None when absent, NaN when it varies)."""
    if values is None:
        return None
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    if not finite.size:
        return None
    return float(finite[0]) if np.ptp(finite) <= 1e-12 * max(1.0, float(np.max(np.abs(finite)))) else math.nan


def friction_curves(reactions: Reactions, direction: int | None = None, points: int = 360) -> dict[str, np.ndarray]:
    """What :func:`plot_friction` draws as curves: on a finer grid of the table's span, or at the
    table positions (``points=0``, or where no finer grid can repeat the table's analysis).

    Parameters
    ----------
    reactions : Reactions
        With friction (``solve_reactions(motion, friction=True)``), at the table positions.
    direction : {1, -1}, optional
        The sense of rotation of the table (default: of its first step, ``motion.direction``).
    points : int
        Size of the finer grid over the table (0: none).

    Returns
    -------
    dict of str -> ndarray (M,)
        ``x`` (``phi_deg``, deg, or ``s``, m), ``efficiency``, ``power_lost`` (W) and
        ``K.power_lost`` (W) for each pair K with friction. On the finer grid when it could be
        made and agrees with the table at the table positions (same speed and acceleration at
        every position, the scheme's own loads), else at the table positions.
    """
    table = _curves(reactions, _positions(reactions, direction))
    if points <= 0 or len(reactions.motion.phi) < 2:
        return table
    motion = reactions.motion
    omega, eps = _uniform(motion.omega), _uniform(motion.eps)
    if (omega is not None and math.isnan(omega)) or (eps is not None and math.isnan(eps)):
        return table     # a law of motion: the speed varies between the rows
    phi = np.asarray(motion.phi, dtype=float)
    fine_phi = _fine_angles(phi, points)
    ends = np.zeros(len(fine_phi), bool)
    ends[-1] = True
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fine_motion = analyze(motion.mechanism, fine_phi, order=2, omega=omega, eps=eps if omega is not None
                                  else None, on_failure="mask")
            fine = solve_reactions(fine_motion, ends=ends, friction=reactions.friction, sense=reactions.sense)
    except (LinkageError, ValueError):
        return table
    x = table_positions_deg(fine_phi, motion.direction if direction is None else direction) \
        if motion.mechanism.coordinate.is_angle else fine_phi
    curves = _curves(fine, x)
    at = np.arange(len(phi)) * ((len(fine_phi) - 1) // (len(phi) - 1))   # the table's rows in the fine grid
    for name, values in table.items():
        here = curves[name][at]
        scale = max(1.0, float(np.nanmax(np.abs(values))) if np.isfinite(values).any() else 1.0)
        same = (np.isnan(here) & np.isnan(values)) | (np.abs(here - values) <= AGREEMENT * scale)
        if not np.all(same):
            return table
    return curves


def _curves(reactions: Reactions, x: np.ndarray) -> dict[str, np.ndarray]:
    out = {"x": np.asarray(x, dtype=float), "efficiency": reactions.efficiency(),
           "power_lost": 0.0 - reactions.friction_power()}
    for pair in sorted(reactions.friction.pairs if reactions.friction else ()):
        out[f"{pair}.power_lost"] = 0.0 - reactions.friction_power(pair)
    if reactions.locked is not None and np.any(reactions.locked):   # self-locking: no value to draw
        for name in out:
            if name != "x":
                out[name] = np.where(reactions.locked, np.nan, out[name])
    return out


def _pair_label(reactions: Reactions, pair: str) -> str:
    """``A (links 1–2): f = 0.08, r = 0.03 m``; a prismatic pair ``slide (P, links 0–3): f = 0.12, block 0.12 m``."""
    p = reactions.friction.pairs[pair]
    links = "–".join(reactions.motion.mechanism.pairs[pair].links)
    prismatic = isinstance(reactions.motion.joints[pair], PrismaticJoint)
    size = (f", block {p.length:g} m" if p.length else "") if prismatic else f", r = {p.radius:g} m"
    return f"{pair} ({'P, ' if prismatic else ''}links {links}): f = {p.f:g}{size}"


def _cycle(reactions: Reactions) -> tuple[CycleWorks | None, str]:
    """The works of one turn at the table's speed, or None and why not."""
    mech = reactions.motion.mechanism
    omega = _uniform(reactions.motion.omega)
    if omega is not None and math.isnan(omega):   # under a law of motion: at its mean speed
        omega = float(np.nanmean(reactions.motion.omega))
    try:
        return cycle_works(mech, omega if omega else None, friction=reactions.friction), ""
    except InputError as exc:
        return None, str(exc)


def plot_friction(reactions: Reactions, direction: int | None = None, *, cycle: CycleWorks | None = None,
                  points: int = 360) -> Figure:
    """Power lost in each pair with friction and the efficiency η over the cycle, two panels.

    Parameters
    ----------
    reactions : Reactions
        With friction, at the table positions (``forces_results(mech, friction=True).reactions``,
        or ``solve_reactions(motion, friction=True)`` at ``linkage.table_angles(mech, 12)``).
    direction : {1, -1}, optional
        The sense of rotation of the table: the x axis is the angle turned from position 1 in
        that direction, ``phi_deg`` (default: the sense of the table's first step).
    cycle : CycleWorks, optional
        The works of one turn (default: :func:`~linkage.kinetostatics.efficiency.cycle_works` at
        the table's speed with the same friction; its efficiency is drawn dashed on panel (b)).
    points : int
        Size of the finer grid of the curves (0: the table positions joined).

    Returns
    -------
    matplotlib Figure
        Axes 0: the powers lost (lines ``gid`` ``"positions:K.power_lost"`` and
        ``"positions:power_lost"`` through the table positions, ``"curve:..."`` the fine curves);
        axes 1: ``"positions:efficiency"``, ``"curve:efficiency"`` and ``"cycle-efficiency"``.

    Raises
    ------
    InputError
        (a ``ValueError``) The reactions have no friction.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    if not reactions.friction:
        raise InputError("the reactions carry no friction: solve them with solve_reactions(motion, friction=True) "
                         "(the scheme's [friction])")
    motion = reactions.motion
    mech = motion.mechanism
    table = _curves(reactions, _positions(reactions, direction))
    curves = friction_curves(reactions, direction, points)
    fine = curves["x"].shape != table["x"].shape
    if cycle is None:
        cycle, why = _cycle(reactions)
    else:
        why = ""
    pairs = [name[: -len(".power_lost")] for name in table if name.endswith(".power_lost")]
    fig = new_figure(PAGE_WIDTH, 7.4)
    grid = fig.add_gridspec(3, 1, height_ratios=[2.6, 2.6, 0.25 + 0.2 * math.ceil((len(pairs) + 3) / 2)])
    losses = fig.add_subplot(grid[0])
    eta = fig.add_subplot(grid[1], sharex=losses)
    key = fig.add_subplot(grid[2])
    key.axis("off")
    ms = 4.5 if len(table["x"]) <= 40 else 3.0
    series = [(f"{p}.power_lost", _pair_label(reactions, p), CURVE_COLOURS[k % len(CURVE_COLOURS)],
               MARKERS[k % len(MARKERS)], 1.4) for k, p in enumerate(pairs)]
    series.append(("power_lost", "power lost in all the pairs", "black", "o", 2.2))
    for name, label, colour, marker, lw in series:
        _draw(losses, table, curves, name, label, colour, marker, lw, ms, fine)
    _draw(eta, table, curves, "efficiency", "efficiency η at each position", CURVE_COLOURS[0], "o", 1.8, ms, fine)
    static = motion.omega is None or not np.any(np.nan_to_num(np.asarray(motion.omega, dtype=float)))
    if cycle is not None and math.isfinite(cycle.efficiency):
        how = "one turn, static" if static else "one turn at constant speed"
        eta.axhline(cycle.efficiency, color="black", ls="--", lw=1.3, gid="cycle-efficiency",
                    label=f"cycle efficiency {cycle.efficiency + 0.0:.4f} ({how}, {cycle.samples} steps)")
    for ax in (losses, eta):
        style_angle_axis(ax, table["x"])
    losses.set_ylim(bottom=0.0)
    values = np.r_[curves["efficiency"], table["efficiency"], 0.0, 1.0]
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    eta.set_ylim(lo - 0.05 * (hi - lo), hi + 0.1 * (hi - lo))
    _extremes(losses, eta, extreme_marks(mech, motion.phi) if mech.output is not None
              and mech.coordinate.is_angle else [])
    unit = ("W" if not static else
            "W per rad/s of input speed" if mech.coordinate.is_angle else "W per m/s of input speed")
    losses.set_ylabel(wrapped_label(f"power lost to friction $P_f$, {unit}", losses), fontsize=FONT)
    eta.set_ylabel("efficiency $\\eta$ (dimensionless)", fontsize=FONT)
    eta.set_xlabel(describe_column(position_column(mech), mech).axis, fontsize=FONT)
    losses.tick_params(labelbottom=False)
    losses.set_title("(a) power lost in each pair and in all", fontsize=SMALL, loc="left")
    eta.set_title("(b) efficiency η = −P_useful / P_driving; dashed: one turn's A_useful / A_driving",
                  fontsize=SMALL, loc="left")
    number_positions(losses, table["x"], np.arange(1, len(table["x"]) + 1))
    handles, labels = [], []
    for ax in (losses, eta):
        for handle, label in zip(*ax.get_legend_handles_labels()):
            handles.append(handle)
            labels.append(label)
    legend = key.legend(handles, labels, loc="center", ncols=2, fontsize=SMALL - 1, frameon=False)
    if legend.get_window_extent(fig.canvas.get_renderer()).width > 0.98 * fig.bbox.width:
        legend.remove()
        key.legend(handles, labels, loc="center", ncols=1, fontsize=SMALL - 1, frameon=False)
        grid.set_height_ratios([2.6, 2.6, 0.25 + 0.2 * len(labels)])
    fit_width(fig.suptitle(f"Friction in the pairs of {mech.name}, {_speed(motion)}", fontsize=FONT))
    caption = ["η is left out where the drive delivers no power (P_driving ≤ 0: the machine is carried by its "
               "inertia, gravity or a load there); it may exceed 1 where they give back energy."]
    if cycle is None:
        caption.append(f"No cycle efficiency: {why}")
    elif cycle.locked:
        caption.append(f"The cycle's works are undefined: the mechanism self-locks at {cycle.locked} of "
                       f"{cycle.samples} positions of the turn.")
    locked = np.flatnonzero(reactions.locked) if reactions.locked is not None else []
    if len(locked):
        caption.append("Self-locking (no value drawn) at position(s) "
                       + ", ".join(str(int(i) + 1) for i in locked) + ".")
    fit_width(fig.supxlabel("\n".join(caption), fontsize=SMALL - 1, color="0.3"))
    return fig


def _extremes(losses, eta, marks: list[tuple[float, str]]) -> None:
    """The output's extreme positions: a line on both panels, its name in a band atop panel (a)."""
    for ax in (losses, eta):
        for x, _ in marks:
            ax.axvline(x, color="0.35", ls="-.", lw=0.9, gid="extreme-position")
    if not marks:
        return
    lo, hi = losses.get_ylim()
    losses.set_ylim(lo, hi + 0.12 * (hi - lo))
    x_lo, x_hi = losses.get_xlim()
    for x, text in marks:
        right = (x - x_lo) / (x_hi - x_lo) > 0.85
        losses.annotate(text, (x, 1.0), xycoords=("data", "axes fraction"), xytext=(-3 if right else 3, -2),
                        textcoords="offset points", ha="right" if right else "left", va="top",
                        fontsize=SMALL, gid="extreme-position-text")


def _speed(motion) -> str:
    words = speed_words(motion)
    return "static: per unit of input speed, no inertia forces" if words.startswith("no speed") else words


def _draw(ax, table, curves, name, label, colour, marker, lw, ms, fine) -> None:
    """A quantity: its fine curve (when there is one) and the table positions marked on it."""
    if fine:
        ax.plot(curves["x"], curves[name], "-", color=colour, lw=lw, label=label, gid=f"curve:{name}")
        ax.plot(table["x"], table[name], ls="none", marker=marker, ms=ms, mfc="white", mec=colour, mew=1.3,
                clip_on=False, zorder=3, gid=f"positions:{name}")
    else:
        ax.plot(table["x"], table[name], "-", color=colour, lw=lw, marker=marker, ms=ms, mfc="white", mec=colour,
                mew=1.3, clip_on=False, zorder=3, label=label, gid=f"positions:{name}")
