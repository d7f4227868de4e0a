"""Diagrams of table columns against the input: the quantity and its unit in words on every axis.

The x axis is ``phi_deg``, psi, the input angle turned from position 1 in the direction of rotation
(``s``, m, for a slide input), and analogs are drawn as derivatives with respect to it, d/dpsi
(d/ds): a curve and its analog agree by graphical differentiation whichever way the crank turns.
The Python API's ``Motion.columns()`` gives d/dphi of the absolute angle; :func:`plot_motion`
turns them into d/dpsi itself, :func:`plot_columns` and :func:`plot_diagrams` with their
``direction`` (docs/conventions.md).

- :func:`plot_columns` -- table columns of one unit on one set of axes: axes labelled with the
  quantity in words and its unit, legends in words
  (:func:`~linkage.report.words.describe_column`), the table positions marked on the curves and
  numbered along the top, extreme positions of the output and the mean driving moment drawn when
  given, angle columns made continuous;
- :func:`plot_diagrams` -- several columns, one panel per unit, over a shared angle axis;
- :func:`plot_motion` -- kinematic diagrams of a :class:`~linkage.Motion` over its table positions
  (smooth curves from a fine analysis, the extreme positions of the output marked);
- :func:`plot_dynamics` -- per-position columns of a dynamics report (the balancing moment with the
  mean driving moment, ω, ε ...);
- :func:`extreme_marks` -- where the extreme positions of the output lie on a table's axis.

The pieces other diagrams share (the machine's, :mod:`linkage.report.machine`): the angle axis
(:func:`style_angle_axis`), the position numbers along the top (:func:`number_positions`), an
axis label on two lines when it is long (:func:`wrapped_label`), one legend under the panels
(:func:`figure_legend`) and the x labels of the lower panel only (:func:`finish_panels`).

Every function returns the matplotlib ``Figure`` or ``Axes``; without matplotlib it raises
:class:`~linkage.report.style.PlotExtraMissing`.
"""

from __future__ import annotations

import math
import re
import warnings
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ..errors import InputError
from ..kinematics.extremes import extreme_positions
from ..kinematics.motion import analyze
from ..model.mechanism import Mechanism
from .style import CURVE_COLOURS, FONT, MARKERS, PAGE_WIDTH, SMALL, new_figure, pyplot
from .tables import column_unit, per_turned_angle
from .words import ColumnWords, describe_column

__all__ = ["extreme_marks", "plot_columns", "plot_diagrams", "plot_motion", "plot_dynamics", "style_angle_axis",
           "number_positions", "wrapped_label", "figure_legend", "finish_panels"]


def _position_name(columns: Mapping[str, Any]) -> str:
    """The position column of a table: ``phi_deg``, or ``s`` (a slide input, m)."""
    return "s" if "s" in columns and "phi_deg" not in columns else "phi_deg"


def _panel_label(described: Sequence[ColumnWords]) -> str:
    """Axis label of a panel: the column's own label, or the family and the symbols of several."""
    if len(described) == 1:
        return described[0].axis
    kinds = list(dict.fromkeys(d.kind for d in described))
    symbols = ", ".join(d.short for d in described if d.short)     # an analog: its derivative
    text = f"{' and '.join(kinds)} {symbols}".strip()
    unit = described[0].unit
    return f"{text}, {unit}" if unit else text


def _is_angle(name: str) -> float | None:
    """The period of an angle column (2 pi for ``L.theta``, 360 for ``*angle_deg``), else None."""
    if name.endswith(".theta"):
        return 2 * np.pi
    if name.endswith("angle_deg"):
        return 360.0
    return None


def _unwrap(values: np.ndarray, period: float) -> np.ndarray:
    """Remove the jumps of a wrapped angle column (NaN rows kept as gaps)."""
    out = np.array(values, dtype=float)
    ok = np.isfinite(out)
    out[ok] = np.unwrap(out[ok], period=period)
    return out


def extreme_marks(mechanism: Mechanism, phi, quantity: str | None = None) -> list[tuple[float, str]]:
    """Where the extreme positions of the output lie on a table's ``phi_deg`` axis (on its ``s``
    axis, m, for a slide input).

    Parameters
    ----------
    mechanism : Mechanism
    phi : array_like
        The table's input angles, rad (``motion.phi``, ``linkage.table_angles(...)``); the table's
        direction is the sense of its first step.
    quantity : str, optional
        The output (default: the mechanism's declared output).

    Returns
    -------
    list of (float, str)
        ``(phi_deg, text)`` of each extreme position within the table (both ends when it falls on
        position 1 of a full turn), e.g. ``(0.0, "x_B max")`` as mathtext; the ``marks`` of
        :func:`plot_columns`.

    Examples
    --------
    >>> import linkage
    >>> mech = linkage.load("slider_crank")
    >>> [(round(d, 2), t) for d, t in extreme_marks(mech, linkage.table_angles(mech, 12))]
    [(0.0, '$x_{\\\\mathrm{B}}$ max'), (182.59, '$x_{\\\\mathrm{B}}$ min'), (360.0, '$x_{\\\\mathrm{B}}$ max')]
    """

    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    ext = extreme_positions(mechanism, quantity)
    steps = np.diff(phi)
    steps = steps[steps != 0]
    s = 1.0 if not len(steps) or steps[0] > 0 else -1.0
    span = abs(phi[-1] - phi[0])
    symbol = describe_column(ext.quantity, mechanism).symbol or ext.quantity
    marks = []
    slide = not mechanism.coordinate.is_angle
    for at, which in ((ext.phi_max, "max"), (ext.phi_min, "min")):
        if slide:   # the table's axis is the slide itself, m
            if min(phi[0], phi[-1]) - 1e-12 <= at <= max(phi[0], phi[-1]) + 1e-12:
                marks.append((float(at), f"{symbol} {which}"))
            continue
        d = s * (at - phi[0])
        if mechanism.input_range is None:
            d = np.mod(d, 2 * np.pi)
            if d > 2 * np.pi - 1e-9:
                d = 0.0
            found = [d] + ([d + 2 * np.pi] if d + 2 * np.pi <= span + 1e-9 else [])
        else:
            found = [d]
        for f in found:
            if -1e-9 <= f <= span + 1e-9:
                marks.append((round(float(np.degrees(f)), 10) + 0.0, f"{symbol} {which}"))
    return sorted(marks)


def style_angle_axis(ax, phi: np.ndarray) -> None:
    from matplotlib.ticker import AutoMinorLocator, MaxNLocator, MultipleLocator

    finite = phi[np.isfinite(phi)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    hi = hi if hi > lo else lo + 1.0
    # a table that runs backwards (a slide decreasing over its stroke): position 1 on the left
    ax.set_xlim((hi, lo) if finite.size > 1 and finite[0] > finite[-1] else (lo, hi))
    inches = ax.get_position().width * ax.figure.get_figwidth()
    if 180 <= hi - lo <= 400:   # a turn: a tick every 30 deg where there is room for 13 labels
        ax.xaxis.set_major_locator(MultipleLocator(30 if inches >= 4.5 else 60 if inches >= 2.4 else 90))
    else:
        ax.xaxis.set_major_locator(MaxNLocator(nbins=max(3, min(12, int(inches / 0.45))), steps=[1, 2, 2.5, 3, 5, 10]))
    ax.xaxis.set_minor_locator(AutoMinorLocator())
    ax.tick_params(labelsize=SMALL)
    ax.grid(True, which="major", alpha=0.35)


def number_positions(ax, phi: np.ndarray, numbers: np.ndarray) -> None:
    """Position numbers along the top of the axes, thinned so that they do not run together."""
    ok = np.isfinite(phi)
    phi, numbers = phi[ok], numbers[ok]
    inches = ax.get_position().width * ax.figure.get_figwidth()
    step = max(1, math.ceil(len(phi) / max(5, int(inches / 0.21))))   # room for two digits each
    keep = np.zeros(len(phi), bool)
    keep[::step] = True
    keep[-1] = True
    if step > 1 and len(phi) > 1 and (len(phi) - 1) % step:
        keep[-1 - ((len(phi) - 1) % step)] = False  # the last two would crowd each other
    top = ax.secondary_xaxis("top")
    top.set_xticks(phi[keep], labels=[str(int(n)) for n in numbers[keep]])
    top.tick_params(labelsize=SMALL, length=3)
    top.set_xlabel("position number", fontsize=SMALL)
    top.set_gid("position-numbers")


def plot_columns(columns: Mapping[str, Any], names: Sequence[str], ax=None, *,
                 mechanism: Mechanism | None = None, fine: Mapping[str, Any] | None = None,
                 marks: Iterable[tuple[float, str]] = (), mean_moment: float | None = None,
                 mean_label: str | None = None, numbers: bool = True, legend: bool | None = None,
                 direction: int = 1):
    """Plot table columns of one unit against the input angle turned, ``phi_deg``.

    The y axis is labelled with the quantity in words and its unit, the legend names the curves
    in words (:func:`~linkage.report.words.describe_column`); every table position is marked on
    each curve and numbered along the top; angle columns are drawn continuous. Analogs are drawn
    with respect to the x axis, d/dpsi (psi = ``phi_deg`` in rad; d/ds for a slide input), so
    that each is the slope of its quantity's curve.

    Parameters
    ----------
    columns : mapping of str -> array
        A table with ``phi_deg`` and, for the numbers, ``i``: a table for people
        (:func:`~linkage.report.results.kinematics_results`, analogs d/dpsi), ``Motion.columns()``
        (analogs d/dphi: give ``direction``), ``Reactions.columns()``,
        ``DynamicsReport.columns()``.
    names : sequence of str
        The columns to plot; all of one unit (:func:`plot_diagrams` puts columns of several units
        on panels of their own).
    ax : matplotlib Axes, optional
        Where to draw (default: a new figure the width of an A4 page's text).
    mechanism : Mechanism, optional
        Names links and points by their role in the words (crank, rocker, slider).
    fine : mapping of str -> array, optional
        The same columns on a finer grid of angles starting at position 1 (a ``columns()`` of a
        finer analysis): drawn as the curves, the table's rows as markers on them. Without it
        the curves join the table's rows.
    marks : iterable of (float, str)
        Vertical lines at these ``phi_deg`` with their text (extreme positions:
        :func:`extreme_marks`).
    mean_moment : float, optional
        A horizontal line at this value (N·m), e.g. the mean driving moment on a moment plot.
    mean_label : str, optional
        Its legend entry (default: ``"mean driving moment <value> N·m"``).
    numbers : bool
        Number the table positions along the top of the axes.
    legend : bool, optional
        Draw a legend (default: when there is more than one entry).
    direction : {1, -1}
        For columns of the Python API (``Motion.columns()``, whose first analogs are d/dphi of
        the absolute input angle): the sense of rotation of their table, ``motion.direction``
        (-1 clockwise); their first analogs (and those of ``fine``) are drawn multiplied by it,
        d/dpsi (:func:`~linkage.report.tables.per_turned_angle`). 1 (default): drawn as given,
        for a table for people, whose analogs are d/dpsi already (or a counter-clockwise one).

    Returns
    -------
    matplotlib Axes

    Raises
    ------
    InputError
        (a ``ValueError``) An unknown column, columns of different units, a table without
        ``phi_deg``.
    PlotExtraMissing
        matplotlib is not installed.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> mech = linkage.load("four_bar")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> ax = plot_columns(motion.columns(), ["3.theta'"], mechanism=mech, direction=motion.direction)
    >>> ax.get_ylabel().replace("\\n", " ")
    'angular velocity analog of rocker 3 $d\\\\theta_{\\\\mathrm{3}}/d\\\\psi$, rad/rad'
    >>> ax.figure.savefig(io.BytesIO(), format="svg")
    >>> matplotlib.pyplot.close(ax.figure)
    """
    pyplot()
    names = list(names)
    missing = [n for n in names if n not in columns]
    position = _position_name(columns)
    if position not in columns:
        missing.insert(0, "phi_deg")
    if missing:
        raise InputError(f"no column {missing[0]!r}; columns: {list(columns)}")
    if not names:
        raise InputError("name at least one column to plot")
    described = [describe_column(n, mechanism) for n in names]
    units = {d.unit for d in described}
    if len(units) > 1:
        raise InputError(f"columns {names} have different units ({', '.join(str(u) for u in units)}): "
                         "plot them with plot_diagrams, one panel per unit")
    if direction != 1:
        columns = per_turned_angle(columns, direction)
        fine = None if fine is None else per_turned_angle(fine, direction)
    if ax is None:
        ax = new_figure(PAGE_WIDTH, 3.8).add_subplot()
    phi = np.asarray(columns[position], dtype=float)
    numbers_col = np.asarray(columns["i"]) if "i" in columns else np.arange(1, len(phi) + 1)
    ms = 5 if len(phi) <= 40 else 3.5
    for k, (name, d) in enumerate(zip(names, described)):
        colour, marker = CURVE_COLOURS[k % len(CURVE_COLOURS)], MARKERS[k % len(MARKERS)]
        values = np.asarray(columns[name], dtype=float)
        period = _is_angle(name)
        if fine is not None and name in fine and position in fine:
            fphi = np.asarray(fine[position], dtype=float)
            fvalues = np.asarray(fine[name], dtype=float)
            if period:
                fvalues = _unwrap(fvalues, period)
                near = np.interp(phi, fphi, fvalues)
                values = values + period * np.round((near - values) / period)
            ax.plot(fphi, fvalues, "-", color=colour, lw=1.8, label=d.legend, gid=f"curve:{name}")
            ax.plot(phi, values, ls="none", marker=marker, ms=ms, mfc="white", mec=colour, mew=1.4,
                    clip_on=False, zorder=3, gid=f"positions:{name}")
        else:
            if period:
                values = _unwrap(values, period)
            ax.plot(phi, values, "-", color=colour, lw=1.8, marker=marker, ms=ms, mfc="white", mec=colour,
                    mew=1.4, clip_on=False, zorder=3, label=d.legend, gid=f"positions:{name}")
    entries = len(names)
    if mean_moment is not None:
        label = mean_label or f"mean driving moment {mean_moment:.4g} N·m"
        ax.axhline(mean_moment, color="black", ls="--", lw=1.3, label=label, gid="mean-moment")
        entries += 1
    style_angle_axis(ax, phi)
    lo, hi = ax.get_ylim()
    if lo < 0 < hi:
        ax.axhline(0.0, color="0.4", lw=0.8, zorder=1)
    marks = list(marks)
    if marks:  # a band above the curves for the marks' texts
        ax.set_ylim(lo, hi + 0.13 * (hi - lo))
        x_lo, x_hi = ax.get_xlim()
    for x, text in marks:
        ax.axvline(x, color="0.25", ls="-.", lw=1.0, gid="extreme-position")
        right = (x - x_lo) / (x_hi - x_lo) > 0.85    # (an axis may run backwards)
        ax.annotate(text, (x, 1.0), xycoords=("data", "axes fraction"), xytext=(-3 if right else 3, -2),
                    textcoords="offset points", ha="right" if right else "left", va="top", fontsize=SMALL,
                    gid="extreme-position-text")
    ax.set_xlabel(describe_column(position, mechanism).axis, fontsize=FONT)
    ax.set_ylabel(wrapped_label(_panel_label(described), ax), fontsize=FONT)
    if legend or (legend is None and entries > 1):
        ax.legend(fontsize=SMALL, loc="best", framealpha=0.9)
    if numbers:
        number_positions(ax, phi, numbers_col)
    return ax


def wrapped_label(label: str, ax) -> str:
    """An axis label on two lines when it is longer than the axes is tall."""
    fig = ax.figure
    height_in = ax.get_position().height * fig.get_figheight()
    if ax.get_subplotspec() is not None:  # constrained layout has not placed it yet: its share
        rows = ax.get_subplotspec().get_gridspec().nrows
        height_in = fig.get_figheight() / rows - 0.5
    probe = fig.text(0, 0, label, fontsize=FONT)
    width_in = probe.get_window_extent(fig.canvas.get_renderer()).width / fig.dpi
    probe.remove()
    if width_in <= 0.95 * height_in:
        return label
    # break before the symbol when the words fit on a line, else at the space nearest the middle
    # (never inside mathtext)
    spaces, offset = [], 0
    for part in re.split(r"(\$[^$]*\$)", label):
        if not part.startswith("$"):
            spaces += [offset + m.start() for m in re.finditer(" ", part)]
        offset += len(part)
    if not spaces:
        return label
    symbol = label.find(" $")
    if symbol > 0 and symbol in spaces and symbol / len(label) * width_in <= 0.95 * height_in:
        cut = symbol
    else:
        cut = min(spaces, key=lambda k: abs(k - len(label) / 2))
    return label[:cut] + "\n" + label[cut + 1:]


def figure_legend(fig, axes) -> None:
    """One legend under the panels, with every curve and line that has a label (once each)."""
    handles, labels = [], []
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    if handles:
        fig.legend(handles, labels, loc="outside lower center", fontsize=SMALL, ncols=1, frameon=False)


def _groups_by_unit(names: Sequence[str]) -> list[list[str]]:
    groups: dict[Any, list[str]] = {}
    for name in names:
        groups.setdefault(column_unit(name), []).append(name)
    return list(groups.values())


def _panels(count: int, height: float = 2.6):
    fig = new_figure(PAGE_WIDTH, min(9.5, 1.6 + height * count) if count > 1 else 4.0)
    axes = fig.subplots(count, 1, sharex=True, squeeze=False)[:, 0]
    return fig, axes


def finish_panels(axes) -> None:
    for ax in axes[:-1]:
        ax.set_xlabel("")
        ax.tick_params(labelbottom=False)


def plot_diagrams(columns: Mapping[str, Any], names: Sequence[str], *, mechanism: Mechanism | None = None,
                  fine: Mapping[str, Any] | None = None, marks: Iterable[tuple[float, str]] = (),
                  mean_moment: float | None = None, mean_label: str | None = None, direction: int = 1):
    """Diagrams of table columns, one panel per unit, over a shared input-angle axis.

    Columns of one unit share a panel (in the order of ``names``); the panels are drawn by
    :func:`plot_columns`, the positions numbered along the top of the first; ``marks`` are drawn
    on every panel, ``mean_moment`` on the panels in N·m.

    Parameters
    ----------
    columns, names, mechanism, fine, marks, mean_moment, mean_label, direction
        As in :func:`plot_columns` (``direction``: the sense of rotation of ``Motion.columns()``,
        whose analogs are d/dphi, so that they are drawn d/dpsi; 1 for a table for people).

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> mech = linkage.load("slider_crank")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> fig = plot_diagrams(motion.columns(), ["B.x", "B.x'", "B.x''"], mechanism=mech, direction=motion.direction)
    >>> [ax.get_ylabel().split("$")[0].strip() for ax in fig.axes if ax.get_ylabel()]
    ['slider position', 'slider velocity analog', 'slider acceleration analog']
    >>> fig.savefig(io.BytesIO(), format="png")
    >>> matplotlib.pyplot.close(fig)
    """
    names = list(names)
    if not names:
        raise InputError("name at least one column to plot")
    missing = [n for n in names if n not in columns]
    if missing:
        raise InputError(f"no column {missing[0]!r}; columns: {list(columns)}")
    marks = list(marks)
    groups = _groups_by_unit(names)
    fig, axes = _panels(len(groups))
    for k, (ax, group) in enumerate(zip(axes, groups)):
        moment = mean_moment if column_unit(group[0]) == "N m" else None
        plot_columns(columns, group, ax, mechanism=mechanism, fine=fine, marks=marks, mean_moment=moment,
                     mean_label=mean_label, numbers=k == 0, legend=False, direction=direction)
    finish_panels(axes)
    if any(len(ax.get_legend_handles_labels()[1]) > 1 for ax in axes):
        figure_legend(fig, axes)
    return fig


def _fine_angles(phi: np.ndarray, points: int = 360) -> np.ndarray:
    """The table's angles with ``k`` equal steps inserted between consecutive rows."""
    if len(phi) < 2:
        return phi.copy()
    k = max(1, math.ceil(points / (len(phi) - 1)))
    return np.interp(np.arange((len(phi) - 1) * k + 1) / k, np.arange(len(phi)), phi)


def plot_motion(motion, names: Sequence[str], *, extremes: bool | str = True, points: int = 360):
    """Kinematic diagrams of a motion analysed at table positions.

    Smooth curves from an analysis on a finer grid (``points`` angles over the table), the table
    rows marked and numbered, the extreme positions of the output marked. The x axis is the angle
    turned from position 1 in the direction of rotation, psi (``phi_deg``), and the analogs are
    drawn d/dpsi = ``motion.direction`` d/dphi (d/ds for a slide input), the slopes of their
    quantities' curves whichever way the crank turns.

    Parameters
    ----------
    motion : Motion
        :func:`linkage.analyze` at the table's angles (e.g. ``linkage.table_angles(mech, 12)``).
    names : sequence of str
        Columns of ``motion.columns()`` (``"B.x"``, ``"B.x'"``, ``"3.theta''"`` ...); one panel
        per unit.
    extremes : bool or str
        Mark the extreme positions of the declared output (True), of a named quantity
        (``"3.theta"``), or none (False).
    points : int
        Size of the fine grid of the curves.

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> mech = linkage.load("slider_crank")
    >>> motion = linkage.analyze(mech, linkage.table_angles(mech, 12))
    >>> fig = plot_motion(motion, ["B.x", "B.x'", "B.x''"])
    >>> fig.savefig(io.BytesIO(), format="svg")
    >>> matplotlib.pyplot.close(fig)
    """

    pyplot()
    mech = motion.mechanism
    direction = motion.direction
    sense = direction if mech.coordinate.is_angle else 1    # a slide input: its analogs are per m of s
    columns = motion.columns()
    order = 2 if motion.second is not None else 1 if motion.first is not None else 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fine_motion = analyze(mech, _fine_angles(np.asarray(motion.phi, dtype=float), points), order=order,
                              on_failure="mask")
    fine = fine_motion.columns(direction=direction)
    marks: list[tuple[float, str]] = []
    if extremes and (isinstance(extremes, str) or mech.output is not None) and len(motion.phi) > 1:
        marks = extreme_marks(mech, motion.phi, extremes if isinstance(extremes, str) else None)
    return plot_diagrams(columns, names, mechanism=mech, fine=fine, marks=marks, direction=sense)


def plot_dynamics(report, names: Sequence[str] = ("balancing_moment",), *, extremes: bool = True):
    """Per-position results of the machine's dynamics (:func:`linkage.dynamics.pipeline.run_dynamics`).

    One panel per column, the table positions marked and numbered, the extreme positions of the
    output marked. Moment panels carry the mean driving moment ``M_d``: on the balancing moment
    (CCW positive) it is drawn at ``s·M_d`` (s the sense of rotation, -1 clockwise), about the
    mean of ``M_b`` over the cycle (``s·M_b = M_d − J_c·ψ̈``, docs/conventions.md); on reduced
    moments (positive when they drive) at ``M_d``.

    Parameters
    ----------
    report : DynamicsReport
    names : sequence of str
        Columns of ``report.columns()``: ``balancing_moment``, ``omega``, ``eps``,
        ``reduced_moment_resistance``, ``reduced_inertia`` ...
    extremes : bool
        Mark the extreme positions of the mechanism's output.

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import io, linkage
    >>> from linkage.dynamics.pipeline import run_dynamics
    >>> report = run_dynamics(linkage.load("course_slider_crank"), compare=False)
    >>> fig = plot_dynamics(report, ["balancing_moment", "omega"])
    >>> fig.legends[0].get_texts()[1].get_text()
    'mean driving moment $M_d$ = 183.5 N·m, acting clockwise (−183.5 N·m on this axis)'
    >>> fig.savefig(io.BytesIO(), format="png")
    >>> matplotlib.pyplot.close(fig)
    """
    pyplot()
    columns = report.columns()
    names = list(names)
    missing = [n for n in names if n not in columns]
    if missing or not names:
        raise InputError(f"no column {missing[0]!r}; columns: {list(columns)}" if missing else
                         "name at least one column to plot")
    mech, law = report.mechanism, report.law
    omega = np.asarray(law.omega, dtype=float)
    s = -1.0 if np.nanmean(omega) < 0 else 1.0
    md = float(law.driving_moment)
    sense = "clockwise" if s < 0 else "counter-clockwise"
    marks = extreme_marks(mech, law.phi) if extremes and mech.output is not None else []
    fig, axes = _panels(len(names))
    for k, (ax, name) in enumerate(zip(axes, names)):
        mean = label = None
        if not math.isfinite(md):
            pass
        elif name == "balancing_moment":
            mean = s * md
            label = f"mean driving moment $M_d$ = {md:.1f} N·m, acting {sense}"
            if s < 0:
                label += f" ({_minus(mean)} N·m on this axis)"
        elif name.startswith("reduced_moment"):
            mean, label = md, f"driving moment $M_d$ = {md:.1f} N·m"
        plot_columns(columns, [name], ax, mechanism=mech, marks=marks, mean_moment=mean, mean_label=label,
                     numbers=k == 0, legend=False)
    finish_panels(axes)
    if any(len(ax.get_legend_handles_labels()[1]) > 1 for ax in axes):
        figure_legend(fig, axes)
    return fig


def _minus(x: float) -> str:
    return f"{x:.1f}".replace("-", "−")
