"""Pictures for people: diagrams of table columns and the mechanism drawn to scale.

Needs the ``plot`` extra (matplotlib). Without it the rest of the library works, and every
function here raises :class:`PlotExtraMissing` (a :class:`~linkage.errors.LinkageError` and an
``ImportError``) saying ``pip install "linkage[plot]"``.

Diagrams (the x axis is ``phi_deg``, the input angle turned from position 1):

- :func:`plot_columns` -- table columns of one unit on one set of axes: axes labelled with the
  quantity in words and its unit, legends in words (:func:`describe_column`), the table positions
  marked on the curves and numbered along the top, extreme positions of the output and the mean
  driving moment drawn when given, angle columns made continuous;
- :func:`plot_diagrams` -- several columns, one panel per unit, over a shared angle axis;
- :func:`plot_motion` -- kinematic diagrams of a :class:`~linkage.Motion` over its table positions
  (smooth curves from a fine analysis, the extreme positions of the output marked);
- :func:`plot_dynamics` -- per-position columns of a dynamics report (the balancing moment with the
  mean driving moment, ω, ε ...).

Drawings of the mechanism, to scale (equal aspect, axes in m), fully inside the frame:

- :func:`draw_mechanism` -- one position: links as lines and polygons, revolute pairs as circles,
  sliders as blocks along their guides, guides and slots, frame pivots and guides hatched, point
  labels placed where they collide with nothing, trajectories of named points;
- :func:`draw_positions` -- several positions side by side at one common scale.

Every function returns the matplotlib ``Figure`` or ``Axes``; save with ``fig.savefig("a.png")``
or ``"a.svg"``.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import numpy as np, linkage
>>> from linkage.report.plots import draw_mechanism
>>> motion = linkage.analyze(linkage.load("slotted_link_two_dyad"), np.radians([30.0]))
>>> ax = draw_mechanism(motion, 0)
>>> ax.get_xlabel(), ax.get_ylabel()
('x, m', 'y, m')
>>> matplotlib.pyplot.close("all")
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from assur.base import global_point

from ..errors import InputError, LinkageError
from ..kinematics.extremes import extreme_positions
from ..kinematics.motion import analyze, input_sweep, table_positions_deg
from ..model.mechanism import Mechanism, Prismatic
from .tables import column_unit

__all__ = ["PlotExtraMissing", "ColumnWords", "describe_column", "link_role", "unit_for_people", "extreme_marks",
           "plot_columns", "plot_diagrams", "plot_motion", "plot_dynamics", "draw_mechanism", "draw_positions"]

#: what to install for pictures
INSTALL_HINT = 'pictures need matplotlib, the optional "plot" extra: pip install "linkage[plot]"'

#: figure width, inches: the text width of an A4 page with 2.5 cm margins (16 cm)
PAGE_WIDTH = 6.3
#: font sizes, points (readable when the figure is printed at PAGE_WIDTH)
FONT = 10
SMALL = 9

#: colours of the moving links (distinct in colour and when printed in grey)
LINK_COLOURS = ("#1f5fa8", "#c0392b", "#27864a", "#7d3c98", "#d35400", "#6b4f2a", "#138d90", "#b03a7a")
#: colours of the curves of a diagram
CURVE_COLOURS = ("#1f5fa8", "#c0392b", "#27864a", "#7d3c98", "#d35400", "#138d90")
MARKERS = ("o", "s", "^", "D", "v", "P")


class PlotExtraMissing(LinkageError, ImportError):
    """matplotlib is not installed: pictures need the ``plot`` extra, ``pip install "linkage[plot]"``."""


def _pyplot():
    """``matplotlib.pyplot``, or :class:`PlotExtraMissing` with the install hint."""
    try:
        import matplotlib  # noqa: F401
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise PlotExtraMissing(INSTALL_HINT) from exc
    return plt


# ----------------------------------------------------------------------------------------------
# names of the columns in words
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ColumnWords:
    """A table column in words.

    Attributes
    ----------
    name : str
        The column name (``"B.x'"``).
    words : str
        What it is (``"velocity analog of B along x"``).
    symbol : str
        Its symbol in matplotlib mathtext (``"$x'_{B}$"``), or ``""``.
    unit : str or None
        Its unit for people (``"m/rad"``, ``"N·m"``, ``"kg·m²"``), None for a pure number.
    kind : str
        The family it belongs to, plural (``"velocity analogs"``): the axis label of a panel that
        holds several columns.
    note : str
        A sign convention the legend adds after the unit (``"CCW positive"``), or ``""``.
    """

    name: str
    words: str
    symbol: str
    unit: str | None
    kind: str
    note: str = ""

    @property
    def axis(self) -> str:
        """Axis label: words, symbol and unit (``"slider position $x_{B}$, m"``)."""
        text = f"{self.words} {self.symbol}".strip()
        return f"{text}, {self.unit}" if self.unit else text

    @property
    def legend(self) -> str:
        """Legend entry: words, symbol and unit (``"velocity analog of B along x $x'_{B}$ (m/rad)"``)."""
        text = f"{self.words} {self.symbol}".strip()
        extra = ", ".join(x for x in (self.unit, self.note) if x)
        return f"{text} ({extra})" if extra else text


def unit_for_people(unit: str | None) -> str | None:
    """``"N m"`` -> ``"N·m"``, ``"m/rad^2"`` -> ``"m/rad²"`` (None stays None)."""
    if not unit:
        return None
    return unit.replace("^2", "²").replace("^3", "³").replace(" ", "·")


def _sub(name: str) -> str:
    """A name as a mathtext subscript: upright, special characters escaped."""
    escaped = re.sub(r"([_$%#&{}^~\\])", r"\\\1", name)
    return "{\\mathrm{" + escaped + "}}"


def _input_word(mech: Mechanism | None) -> str:
    """``"crank"`` (the input turns fully; also when unknown), ``"input link"`` (an angle over a
    range), ``"input slider"`` (a link driven along a frame guide) or ``"cylinder"`` (a driven
    prismatic pair between two moving links)."""
    if mech is None or not mech.inputs:
        return "crank"
    if not mech.coordinate.is_angle:
        return "cylinder" if mech.inputs[0] in mech.pairs else "input slider"
    return "input link" if mech.input_range is not None else "crank"


def _position_name(columns: Mapping[str, Any]) -> str:
    """The position column of a table: ``phi_deg``, or ``s`` (a slide input, m)."""
    return "s" if "s" in columns and "phi_deg" not in columns else "phi_deg"


def link_role(mech: Mechanism, link: str) -> str:
    """The role of a link in words: ``crank`` (``input link`` over an input range), ``slider`` (on
    a guide of the frame), ``rocker`` (pivoted on the frame), ``block`` (a one-point link sliding
    in a moving guide), ``coupler`` (any other), ``frame``."""
    if link == mech.frame:
        return "frame"
    if link in mech.inputs:
        return _input_word(mech)
    pairs = [p for p in mech.pairs.values() if link in p.links]
    if any(isinstance(p, Prismatic) and p.links == (mech.frame, link) for p in pairs):
        return "slider"
    if any(not isinstance(p, Prismatic) and mech.frame in p.links for p in pairs):
        return "rocker"
    if len(mech.links[link].points) == 1 and any(isinstance(p, Prismatic) and p.links[1] == link for p in pairs):
        return "block"
    return "coupler"


def _slider_axis(mech: Mechanism, point: str, axis: int) -> bool:
    """Whether ``point`` is a slider's point on a frame guide along the global ``axis`` (0 x, 1 y)."""
    for pair in mech.pairs.values():
        if isinstance(pair, Prismatic) and pair.links[0] == mech.frame and pair.point == point:
            guide = mech.links[mech.frame].guides.get(pair.guide)
            if guide is not None and abs((math.cos, math.sin)[axis](guide.angle)) > 0.999:
                return True
    return False


_PRIMES = ("", "'", "''")
_ORDER_WORDS = ("", "velocity analog", "acceleration analog")

#: whole-name columns: words, symbol, family ({crank} is the input link's role)
_NAMED = {
    "i": ("position number", "$i$", "position numbers"),
    "phi_deg": ("{crank} angle from the start", r"$\varphi$", "angles"),
    "s": ("slide of the {crank}", "$s$", "slides"),
    "balancing_force": ("balancing force on the {crank}", "$F_b$", "forces"),
    "v": ("speed of the {crank}", "$v$", "speeds"),
    "a": ("acceleration of the {crank}", "$a$", "accelerations"),
    "force": ("force of the actuator", "$F$", "forces"),
    "reduced_force": ("reduced force", "$F_{red}$", "forces"),
    "reduced_mass": ("reduced mass", "$m_{red}$", "masses"),
    "t": ("time", "$t$", "times"),
    "omega": ("angular velocity of the {crank}", r"$\omega$", "angular velocities"),
    "eps": ("angular acceleration of the {crank}", r"$\varepsilon$", "angular accelerations"),
    "balancing_moment": ("balancing moment on the {crank}", "$M_b$", "moments"),
    "reduced_moment_resistance": ("reduced moment of the resistance and gravity", "$M_c$", "moments"),
    "reduced_moment_driving": ("reduced moment of the driving loads", "", "moments"),
    "reduced_inertia": ("reduced moment of inertia", "$I$", "moments of inertia"),
    "reduced_inertia_derivative": ("derivative of the reduced moment of inertia", r"$dI/d\psi$",
                                   "derivatives of the moment of inertia"),
}

#: sign conventions the legends repeat (docs/conventions.md)
_NOTES = {"balancing_moment": "CCW positive", "balancing_force": "positive along +s",
          "reduced_moment_resistance": "positive when driving",
          "reduced_moment_driving": "positive when driving"}


def describe_column(name: str, mechanism: Mechanism | None = None) -> ColumnWords:
    """A table column in words, with its symbol and unit (from :func:`~linkage.report.tables.column_unit`).

    The words follow from the column name (docs/conventions.md, "What the columns mean"); with the
    mechanism they also name the role of the link or point (crank, rocker, slider ...).

    Parameters
    ----------
    name : str
        A column name: ``"B.x"``, ``"B.x'"``, ``"3.theta''"``, ``"slide.s"``, ``"A.R"``,
        ``"balancing_moment"``, ``"phi_deg"`` ...
    mechanism : Mechanism, optional
        The mechanism the column belongs to.

    Returns
    -------
    ColumnWords
        ``.axis`` and ``.legend`` are ready-made labels.

    Examples
    --------
    >>> import linkage
    >>> mech = linkage.load("slider_crank")
    >>> describe_column("B.x", mech).axis
    'slider position $x_{\\\\mathrm{B}}$, m'
    >>> describe_column("B.x'").legend
    "velocity analog of B along x $x'_{\\\\mathrm{B}}$ (m/rad)"
    >>> describe_column("phi_deg", mech).axis
    'crank angle from the start $\\\\varphi$, deg'
    >>> describe_column("3.theta", linkage.load("four_bar")).words
    'angle of rocker 3'
    """
    per = mechanism.coordinate.unit if mechanism is not None and mechanism.inputs else "rad"
    unit = unit_for_people(column_unit(name, per))
    crank = _input_word(mechanism)
    several = mechanism is not None and len(mechanism.inputs) > 1
    if name in _NAMED:
        words, symbol, kind = _NAMED[name]
        note = _NOTES.get(name, "")
        if several and name == "balancing_moment":      # several inputs: name the first
            first = mechanism.inputs[0]
            words, symbol = f"balancing moment on {crank} {first}", f"$M_{{b,{_sub(first)}}}$"
        return ColumnWords(name, words.format(crank=crank), symbol, unit, kind, note)
    obj, dot, quantity = name.rpartition(".")
    if obj == "balancing_moment":                       # a further input link's
        role = link_role(mechanism, quantity) if mechanism is not None and quantity in mechanism.links else "link"
        return ColumnWords(name, f"balancing moment on {role} {quantity}", f"$M_{{b,{_sub(quantity)}}}$", unit,
                           "moments", _NOTES["balancing_moment"])
    base = quantity.rstrip("'")
    order = len(quantity) - len(base)
    if not dot or order > 2:
        return ColumnWords(name, name, "", unit, name)
    sub, prime = _sub(obj), _PRIMES[order]
    if base in ("x", "y"):
        axis = "xy".index(base)
        symbol = f"${base}{prime}_{sub}$"
        if mechanism is not None and _slider_axis(mechanism, obj, axis):
            words = ("slider position", "slider velocity analog", "slider acceleration analog")[order]
        else:
            words = f"{base} coordinate of {obj}" if order == 0 else f"{_ORDER_WORDS[order]} of {obj} along {base}"
        kind = ("coordinates", "velocity analogs", "acceleration analogs")[order]
        return ColumnWords(name, words, symbol, unit, kind)
    if base == "theta":
        role = link_role(mechanism, obj) if mechanism is not None and obj in mechanism.links else "link"
        what = ("angle", "angular velocity analog", "angular acceleration analog")[order]
        kind = ("link angles", "angular velocity analogs", "angular acceleration analogs")[order]
        return ColumnWords(name, f"{what} of {role} {obj}", f"$\\theta{prime}_{sub}$", unit, kind)
    if base == "s":
        words = "slide in pair " + obj if order == 0 else f"{_ORDER_WORDS[order]} of the slide in pair {obj}"
        kind = ("slides", "velocity analogs", "acceleration analogs")[order]
        return ColumnWords(name, words, f"$s{prime}_{sub}$", unit, kind)
    if order == 0 and base in ("R", "Rx", "Ry"):
        words = {"R": f"reaction in pair {obj}", "Rx": f"x component of the reaction in pair {obj}",
                 "Ry": f"y component of the reaction in pair {obj}"}[base]
        symbol = {"R": f"$R_{sub}$", "Rx": f"$R_{{{sub},x}}$", "Ry": f"$R_{{{sub},y}}$"}[base]
        return ColumnWords(name, words, symbol, unit, "reactions")
    if order == 0 and base == "angle_deg":
        return ColumnWords(name, f"direction of the reaction in pair {obj}", f"$\\alpha_{sub}$", unit,
                           "directions of reactions")
    if order == 0 and base == "M":
        return ColumnWords(name, f"moment in pair {obj}", f"$M_{sub}$", unit, "moments", "CCW positive")
    return ColumnWords(name, name, "", unit, name)


def _panel_label(described: Sequence[ColumnWords]) -> str:
    """Axis label of a panel: the column's own label, or the family and the symbols of several."""
    if len(described) == 1:
        return described[0].axis
    kinds = list(dict.fromkeys(d.kind for d in described))
    symbols = ", ".join(d.symbol for d in described if d.symbol)
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


# ----------------------------------------------------------------------------------------------
# diagrams of table columns
# ----------------------------------------------------------------------------------------------


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


def _new_figure(width: float, height: float, layout: str | None = "constrained"):
    plt = _pyplot()
    return plt.figure(figsize=(width, height), layout=layout)


def _style_angle_axis(ax, phi: np.ndarray) -> None:
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


def _number_positions(ax, phi: np.ndarray, numbers: np.ndarray) -> None:
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
                 mean_label: str | None = None, numbers: bool = True, legend: bool | None = None):
    """Plot table columns of one unit against the input angle ``phi_deg``.

    The y axis is labelled with the quantity in words and its unit, the legend names the curves
    in words (:func:`describe_column`); every table position is marked on each curve and numbered
    along the top; angle columns are drawn continuous.

    Parameters
    ----------
    columns : mapping of str -> array
        A table with ``phi_deg`` and, for the numbers, ``i`` (``Motion.columns()``,
        ``Reactions.columns()``, ``DynamicsReport.columns()``).
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
    >>> ax = plot_columns(motion.columns(), ["3.theta'"], mechanism=mech)
    >>> ax.get_ylabel().replace("\\n", " ")
    "angular velocity analog of rocker 3 $\\\\theta'_{\\\\mathrm{3}}$, rad/rad"
    >>> ax.figure.savefig(io.BytesIO(), format="svg")
    >>> matplotlib.pyplot.close(ax.figure)
    """
    _pyplot()
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
    if ax is None:
        ax = _new_figure(PAGE_WIDTH, 3.8).add_subplot()
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
    _style_angle_axis(ax, phi)
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
    ax.set_ylabel(_wrapped(_panel_label(described), ax), fontsize=FONT)
    if legend or (legend is None and entries > 1):
        ax.legend(fontsize=SMALL, loc="best", framealpha=0.9)
    if numbers:
        _number_positions(ax, phi, numbers_col)
    return ax


def _wrapped(label: str, ax) -> str:
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


def _figure_legend(fig, axes) -> None:
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
    fig = _new_figure(PAGE_WIDTH, min(9.5, 1.6 + height * count) if count > 1 else 4.0)
    axes = fig.subplots(count, 1, sharex=True, squeeze=False)[:, 0]
    return fig, axes


def _finish_panels(axes) -> None:
    for ax in axes[:-1]:
        ax.set_xlabel("")
        ax.tick_params(labelbottom=False)


def plot_diagrams(columns: Mapping[str, Any], names: Sequence[str], *, mechanism: Mechanism | None = None,
                  fine: Mapping[str, Any] | None = None, marks: Iterable[tuple[float, str]] = (),
                  mean_moment: float | None = None, mean_label: str | None = None):
    """Diagrams of table columns, one panel per unit, over a shared input-angle axis.

    Columns of one unit share a panel (in the order of ``names``); the panels are drawn by
    :func:`plot_columns`, the positions numbered along the top of the first; ``marks`` are drawn
    on every panel, ``mean_moment`` on the panels in N·m.

    Parameters
    ----------
    columns, names, mechanism, fine, marks, mean_moment, mean_label
        As in :func:`plot_columns`.

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
    >>> fig = plot_diagrams(motion.columns(), ["B.x", "B.x'", "B.x''"], mechanism=mech)
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
                     mean_label=mean_label, numbers=k == 0, legend=False)
    _finish_panels(axes)
    if any(len(ax.get_legend_handles_labels()[1]) > 1 for ax in axes):
        _figure_legend(fig, axes)
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
    rows marked and numbered, the extreme positions of the output marked.

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

    _pyplot()
    mech = motion.mechanism
    columns = motion.columns()
    direction = motion.direction
    order = 2 if motion.second is not None else 1 if motion.first is not None else 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fine_motion = analyze(mech, _fine_angles(np.asarray(motion.phi, dtype=float), points), order=order,
                              on_failure="mask")
    fine = fine_motion.columns(direction=direction)
    marks: list[tuple[float, str]] = []
    if extremes and (isinstance(extremes, str) or mech.output is not None) and len(motion.phi) > 1:
        marks = extreme_marks(mech, motion.phi, extremes if isinstance(extremes, str) else None)
    return plot_diagrams(columns, names, mechanism=mech, fine=fine, marks=marks)


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
    _pyplot()
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
    _finish_panels(axes)
    if any(len(ax.get_legend_handles_labels()[1]) > 1 for ax in axes):
        _figure_legend(fig, axes)
    return fig


def _minus(x: float) -> str:
    return f"{x:.1f}".replace("-", "−")


# ----------------------------------------------------------------------------------------------
# the mechanism to scale
# ----------------------------------------------------------------------------------------------


@dataclass
class _Scene:
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


def _global(motion, link: str, local, rows) -> np.ndarray:
    return global_point(motion.poses[link][rows], local)


def _local_along(pose: np.ndarray, guide, p: np.ndarray) -> np.ndarray:
    """Coordinates along a guide (in its link, pose ``(N, 3)``) of global points ``p`` ``(N, 2)``."""
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    d = p - pose[:, :2]
    local = np.stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]], axis=1)
    return (local - np.asarray(guide.point)) @ np.array(guide.direction)


def _hull(pts: np.ndarray) -> np.ndarray:
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


class _Geometry:
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

    def scene(self, i: int) -> _Scene:
        mech, m, u = self.mech, self.motion, self.unit
        rows = slice(i, i + 1)
        sc = _Scene()
        for name, local in mech.links[mech.frame].points.items():
            sc.points[name] = np.asarray(local, dtype=float)
        for link in mech.moving_links:
            if link not in m.poses:
                continue
            for name, local in mech.links[link].points.items():
                sc.points.setdefault(name, _global(m, link, local, rows)[0])
        pair_points, pivots = set(), []
        for pair in mech.pairs.values():
            if isinstance(pair, Prismatic):
                glink, slider = pair.links
                if slider not in m.poses:
                    continue
                guide = mech.links[glink].guides[pair.guide]
                pose = np.zeros((1, 3)) if glink == mech.frame else m.poses[glink][rows]
                angle = float(pose[0, 2] + guide.angle)
                centre = _global(m, slider, mech.links[slider].points[pair.point], rows)[0]
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
                sc.bodies.append((link, _hull(pts)))
        sc.dots = [n for n in sc.points if n not in pair_points]
        for name in self.trajectories:
            sc.trajectories.append((name, mech.point_link(name), self._sweep_points(name)))
        samples = _samples(sc, u)
        sc.pivots = [(p, _pivot_direction(p, sc, u, samples)) for p in pivots]
        return sc

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


def _support(p: np.ndarray, direction: float, u: float):
    """A frame pivot's support towards ``direction`` (rad): triangle, base and hatching."""
    d = np.array([math.cos(direction), math.sin(direction)])
    n = np.array([-d[1], d[0]])
    base = p + 1.9 * u * d
    triangle = np.array([p, base + 0.95 * u * n, base - 0.95 * u * n])
    ground = np.array([base + 1.5 * u * n, base - 1.5 * u * n])
    strokes = [(base + t * u * n, base + t * u * n + 0.7 * u * (d - n)) for t in np.linspace(-1.5, 1.5, 6)]
    return triangle, ground, np.array(strokes)


def _rail_hatch(line: np.ndarray, side: np.ndarray, u: float):
    """The surface line of a frame guide at half a block's height on ``side``, and its hatching."""
    offset = 0.7 * u * side
    surface = line + offset
    direction = (line[1] - line[0]) / np.linalg.norm(line[1] - line[0])
    length = np.linalg.norm(line[1] - line[0])
    ts = np.arange(0.35 * u, length, 0.9 * u)
    strokes = np.array([(surface[0] + t * direction, surface[0] + t * direction + 0.7 * u * (side - direction))
                        for t in ts])
    return surface, strokes


def _angle_gap(a: float, others: Sequence[float]) -> float:
    """Smallest angle between ``a`` and any of ``others`` (rad; pi when there are none)."""
    if not others:
        return math.pi
    return min(abs((a - b + math.pi) % (2 * math.pi) - math.pi) for b in others)


def _samples(sc: _Scene, u: float) -> np.ndarray:
    """Points along everything drawn at a scene except the supports, spaced u/3."""
    lines = [poly if len(poly) < 3 else np.vstack([poly, poly[:1]]) for _, poly in sc.bodies]
    lines += [line for _, line in sc.slots]
    for line, side in sc.rails:
        lines += [line, _rail_hatch(line, side, u)[0]]
    lines += [np.vstack([r := _rect(c, a, *_block_size(u, f)), r[:1]]) for _, c, a, f in sc.blocks]
    lines += [curve for _, _, curve in sc.trajectories]
    out = []
    for pts in lines:
        for a, b in zip(pts[:-1], pts[1:]):
            k = max(2, int(np.hypot(*(b - a)) / (u / 3)) + 1)
            out.append(a + np.linspace(0.0, 1.0, k)[:, None] * (b - a))
    out = np.vstack(out) if out else np.zeros((0, 2))
    return out[np.all(np.isfinite(out), axis=1)]


#: directions of a frame pivot's support, deg, in order of preference: down, then a wall on
#: either side, then up, then the diagonals
_SUPPORT_DIRECTIONS = (-90, 180, 0, 90, -135, -45, 135, 45, -112.5, -67.5, -157.5, -22.5, 157.5, 22.5, 112.5,
                       67.5)


def _pivot_direction(p: np.ndarray, sc: _Scene, u: float, samples: np.ndarray | None = None) -> float:
    """Direction (rad) of a pivot's support: the first of :data:`_SUPPORT_DIRECTIONS` (down
    first) whose triangle, base and hatching cover the fewest points of the links, guides, blocks
    and trajectories."""
    samples = _samples(sc, u) if samples is None else samples
    samples = samples[np.hypot(*(samples - p).T) > 0.5 * u]
    best, best_cost = -math.pi / 2, math.inf
    for rank, deg in enumerate(_SUPPORT_DIRECTIONS):
        a = math.radians(deg)
        tri, ground, strokes = _support(p, a, u)
        region = _hull(np.vstack([tri, ground, strokes.reshape(-1, 2)]))
        covered = int(np.sum(_inside(region, samples[np.hypot(*(samples - p).T) < 3.5 * u])))
        cost = covered + 0.1 * rank
        if cost < best_cost:
            best, best_cost = a, cost
    return best


class _Drawn:
    """Obstacles of the drawing for the label placement, in data coordinates."""

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


def _limits(sc_list: Sequence[_Scene], geometry: _Geometry) -> tuple[float, float, float, float]:
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
            surface, strokes = _rail_hatch(line, side, u)
            pts += list(line) + list(surface) + list(strokes.reshape(-1, 2))
        for _, centre, angle, on_frame in sc.blocks:
            pts += list(_rect(centre, angle, *_block_size(u, on_frame)))
        for p, direction in sc.pivots:
            tri, ground, strokes = _support(p, direction, u)
            pts += list(tri) + list(ground) + list(strokes.reshape(-1, 2))
        for _, _, curve in sc.trajectories:
            pts += list(curve)
    pts = np.array(pts, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = max(float(max(hi - lo)), geometry.span)
    margin = 0.09 * span
    return lo[0] - margin, hi[0] + margin, lo[1] - margin, hi[1] + margin


def _block_size(u: float, on_frame: bool) -> tuple[float, float]:
    return (3.0 * u, 1.4 * u) if on_frame else (2.0 * u, 1.1 * u)


def _caption(motion, i: int, trajectories: Sequence[str] = (), compact: bool = False) -> str:
    """The position number and the input angle in words (and what the dashed lines are), in lines
    that fit above a drawing: :data:`CAPTION_CHARS` (:data:`COMPACT_CHARS` for a panel of a grid)."""

    mech = motion.mechanism
    if not mech.coordinate.is_angle:
        return _wrapped_caption(mech, _slide_phrases(motion, i, compact), trajectories, compact)
    direction = motion.direction
    turned = float(table_positions_deg(motion.phi, direction)[i])
    sense = "counter-clockwise" if direction > 0 else "clockwise"
    absolute = float(np.mod(np.degrees(motion.phi[i]), 360.0))
    if absolute >= 359.95:
        absolute = 0.0
    who = "input link" if mech.input_range is not None else "crank"
    of = f" of {len(motion.phi)}" if len(motion.phi) > 1 else ""
    head = f"Position {i + 1}{of}"
    at = f"φ = {absolute:.1f}°" if compact else f"φ = {absolute:.1f}° from the x axis"
    if i == 0 or len(motion.phi) == 1:
        phrases = [f"{head}:", f"the {who} at {at}"]
    else:
        phrases = [f"{head}:", f"the {who} turned {turned:.4g}°", sense, "from position 1", f"({at})"]
    return _wrapped_caption(mech, phrases, trajectories, compact)


def _slide_phrases(motion, i: int, compact: bool) -> list[str]:
    """The phrases of a caption for a slide input: how far it moved from position 1, and where."""
    mech = motion.mechanism
    who = _input_word(mech)
    s0, s = float(motion.phi[0]), float(motion.phi[i])
    of = f" of {len(motion.phi)}" if len(motion.phi) > 1 else ""
    head = f"Position {i + 1}{of}"
    at = f"s = {s:.4g} m"
    if i == 0 or len(motion.phi) == 1:
        return [f"{head}:", f"the {who} at {at}"]
    moved = s - s0
    if who == "cylinder":
        verb = "extended" if moved >= 0 else "retracted"
        return [f"{head}:", f"the {who} {verb} by {abs(moved):.4g} m", "from position 1", f"({at})"]
    return [f"{head}:", f"the {who} moved {abs(moved):.4g} m", "towards +s" if moved >= 0 else "towards −s",
            "from position 1", f"({at})"]


def _wrapped_caption(mech, phrases: list[str], trajectories: Sequence[str], compact: bool) -> str:
    """Whole phrases to a line while they fit, then what the dashed lines are."""
    import textwrap

    width = COMPACT_CHARS if compact else CAPTION_CHARS
    lines = [""]
    for phrase in phrases:   # whole phrases to a line while they fit
        if lines[-1] and len(lines[-1]) + 1 + len(phrase) > width:
            lines.append(phrase)
        else:
            lines[-1] = f"{lines[-1]} {phrase}".strip()
    if trajectories and not compact:
        lines += textwrap.wrap(_trajectory_note(mech, trajectories), width)
    return "\n".join(lines)


#: characters per line of a caption above a drawing (10 pt, from the axes' left edge to the page's)
CAPTION_CHARS = 62
#: characters per line of a caption above a panel of a grid of drawings (9 pt, centred)
COMPACT_CHARS = 40


def _trajectory_note(mech: Mechanism, trajectories: Sequence[str]) -> str:
    over = "over the input range" if mech.input_range is not None else "over a turn"
    return f"dashed: trajectory of {', '.join(trajectories)} {over}"


def _figure_for(limits, panels: int = 1, ncols: int = 1, caption_lines: int = 2, header_lines: int = 0,
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
    fig = _new_figure(fig_w, fig_h, layout=None)
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
    Position 4 of 13: the crank turned 90° counter-clockwise
    from position 1 (φ = 325.8° from the x axis)
    dashed: trajectory of E over a turn
    >>> ax.figure.savefig(io.BytesIO(), format="png")
    >>> ax.figure.savefig(io.BytesIO(), format="svg")
    >>> matplotlib.pyplot.close(ax.figure)
    """
    _pyplot()
    i = _index(motion, position)
    geometry = _Geometry(motion, [i], trajectories)
    sc = geometry.scene(i)
    limits = limits or _limits([sc], geometry)
    text = _caption(motion, i, trajectories) if caption is True else (caption or "")
    if ax is None:
        fig, rects = _figure_for(limits, caption_lines=text.count("\n") + 1 if text else 0,
                                 text_chars=max((len(line) for line in text.splitlines()), default=0))
        ax = fig.add_axes(rects[0])
    _draw_scene(ax, sc, geometry, limits, labels, text)
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
    _pyplot()
    n = len(motion.phi)
    if positions is None:
        last = n - 1 if n > 1 and abs(abs(motion.phi[-1] - motion.phi[0]) - 2 * np.pi) < 1e-9 else n
        positions = sorted({int(round(k * last / 4)) for k in range(4)}) if last >= 4 else list(range(last))
    idx = [_index(motion, p) for p in positions]
    if not idx:
        raise InputError("name at least one position to draw")
    geometry = _Geometry(motion, idx, trajectories)
    scenes = [geometry.scene(i) for i in idx]
    limits = _limits(scenes, geometry)
    aspect = (limits[3] - limits[2]) / (limits[1] - limits[0])
    if ncols is None:
        ncols = 1 if len(idx) == 1 or aspect < 0.45 else 2
    compact = ncols > 1
    texts = [_caption(motion, i, compact=compact) for i in idx]
    lines = max(t.count("\n") + 1 for t in texts)
    who = _input_word(motion.mechanism)
    what = (f"; φ: the {who}'s angle from the x axis" if motion.mechanism.coordinate.is_angle else
            f"; s: the {who}'s slide, m")
    header = [f"{motion.mechanism.name} at {len(idx)} positions, one scale" + (what if compact else "")]
    if trajectories:
        header.append(_trajectory_note(motion.mechanism, trajectories))
    chars = max(len(line) for line in texts[0].splitlines() + header)
    fig, rects = _figure_for(limits, len(idx), ncols, caption_lines=lines, header_lines=len(header),
                             text_chars=chars)
    if header:
        fig.suptitle("\n".join(header), fontsize=FONT, y=1 - 0.08 / fig.get_figheight(), va="top")
    for rect, sc, text in zip(rects, scenes, texts):
        ax = fig.add_axes(rect)
        _draw_scene(ax, sc, geometry, limits, labels, text, font=FONT if ncols == 1 else SMALL, centred=True)
    return fig


def _draw_scene(ax, sc: _Scene, geometry: _Geometry, limits, labels, caption: str, font: int = FONT,
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
        surface, strokes = _rail_hatch(line, side, u)
        ax.plot(line[:, 0], line[:, 1], color="0.35", lw=0.8, ls=(0, (8, 3, 2, 3)), zorder=2, gid="guide")
        ax.plot(surface[:, 0], surface[:, 1], color="black", lw=1.4, zorder=2, gid="guide-surface")
        ax.add_collection(LineCollection(strokes, colors="black", linewidths=0.8, zorder=2, gid="hatching"))
    # frame pivots' supports
    for p, direction in sc.pivots:
        tri, ground, strokes = _support(p, direction, u)
        ax.add_patch(Polygon(tri, closed=True, fc="white", ec="black", lw=1.2, zorder=3, gid="support"))
        ax.plot(ground[:, 0], ground[:, 1], color="black", lw=1.4, zorder=3, gid="support-base")
        ax.add_collection(LineCollection(strokes, colors="black", linewidths=0.8, zorder=3, gid="hatching"))
    # links, slots, sliders and blocks, pairs and points
    _add_artists(ax, _moving_artists(sc, geometry))
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
        _place_labels(ax, sc, wanted, _obstacles(sc, u), font, PIN * u)


#: radius of a revolute pair's circle and of a point's dot, in the drawing's unit (a tenth of
#: the mechanism's size: :attr:`_Geometry.unit`)
PIN = 0.42
DOT = 0.22


def _obstacles(sc: _Scene, u: float, base: _Drawn | None = None, trajectory_step: int = 1) -> _Drawn:
    """What the labels of a scene must keep clear of (added to a copy of ``base``): every line,
    area and disc drawn; trajectories at every ``trajectory_step``-th point (light obstacles: a
    film searches its labels' places quicker on fewer segments)."""
    drawn = _Drawn()
    if base is not None:
        drawn.segments, drawn.light = list(base.segments), list(base.light)
        drawn.discs, drawn.areas = list(base.discs), list(base.areas)
    for _, _, curve in sc.trajectories:
        drawn.polyline(np.vstack([curve[::trajectory_step], curve[-1:]]), light=True)
    for line, side in sc.rails:
        surface, strokes = _rail_hatch(line, side, u)
        for polyline in (line, surface, *strokes):
            drawn.polyline(polyline)
    for p, direction in sc.pivots:
        tri, ground, strokes = _support(p, direction, u)
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
    drawn.discs += [(p, PIN * u) for _, p in sc.pins] + [(sc.points[n], DOT * u) for n in sc.dots]
    return drawn


def _moving_artists(sc: _Scene, geometry: _Geometry) -> list:
    """The artists of a scene's moving parts: links, slots, sliders and blocks, pairs and points
    (colours, widths, layers and ids shared by the drawings and the film; add them with
    :func:`_add_artists`)."""
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
    for name, p in sc.pins:
        out.append(Circle(p, PIN * u, fc="white", ec="black", lw=1.4, zorder=8, gid=f"pair:{name}"))
    for name in sc.dots:
        out.append(Circle(sc.points[name], DOT * u, fc="black", ec="none", zorder=8, gid=f"point:{name}"))
    return out


def _add_artists(ax, artists: list) -> list:
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
# labels that collide with nothing
# ----------------------------------------------------------------------------------------------


def _clip_lengths(seg: np.ndarray, boxes: np.ndarray) -> np.ndarray:
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


def _inside(poly: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Which of the points ``(N, 2)`` lie inside the polygon ``poly`` ``(V, 2)``."""
    from matplotlib.path import Path

    pts = np.atleast_2d(pts)
    if len(poly) < 3 or not len(pts):
        return np.zeros(len(pts), bool)
    return Path(poly).contains_points(pts)


def _place_labels(ax, sc: _Scene, names: Sequence[str], drawn: _Drawn, font: int, pin_radius: float) -> None:
    """Write the point names where they cover no line, symbol or other label, inside the axes.

    Works in display coordinates: each label tries 24 directions at three distances from its
    point and takes the candidate of least penalty: outside the axes, on another label, on a
    pair's circle, on a line (by the length covered), inside a link or block, far from its point
    or from the direction away from its links. Deterministic.
    """
    fig = ax.figure
    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()
    to_px = ax.transData.transform
    scale = fig.dpi / 72.0
    frame = ax.get_window_extent(renderer)
    inner = np.array([frame.x0 + 2, frame.y0 + 2, frame.x1 - 2, frame.y1 - 2])
    px_per_m = abs(to_px(np.array([[1.0, 0.0]]))[0, 0] - to_px(np.array([[0.0, 0.0]]))[0, 0])

    def px(segs):
        segs = [x for x in segs if len(x)]
        if not segs:
            return np.zeros((0, 4))
        s = np.vstack(segs)
        return np.hstack([to_px(s[:, :2]), to_px(s[:, 2:])])

    heavy, light = px(drawn.segments), px(drawn.light)
    discs = [(to_px(c[None])[0], r * px_per_m) for c, r in drawn.discs]
    areas = [to_px(a) for a in drawn.areas]
    r_pin = pin_radius * px_per_m
    placed = np.zeros((0, 4))
    centre_all = np.mean(np.array(list(sc.points.values())), axis=0)
    pin_points = _pin_points(sc)
    order = sorted(names, key=lambda n: (n not in pin_points, n))   # pairs first: the most crowded
    steps = 2 * np.pi * np.arange(24) / 24
    for name in order:
        p = sc.points[name]
        away = _away(sc, name, p, centre_all)
        text = ax.annotate(name, p, xytext=(0, 0), textcoords="offset points", ha="center", va="center",
                           fontsize=font, zorder=12, annotation_clip=False, gid=f"label:{name}",
                           bbox=dict(boxstyle="square,pad=0.08", fc="white", ec="none", alpha=0.75))
        bb = text.get_window_extent(renderer)
        w, h = bb.width + 2, bb.height + 1
        p_px = to_px(p[None])[0]
        ring = np.repeat(np.arange(3), len(steps))
        angle = away + np.tile(steps, 3)
        d = np.stack([np.cos(angle), np.sin(angle)], axis=1)
        dist = r_pin + 3 + 5 * scale * ring + np.abs(d[:, 0]) * w / 2 + np.abs(d[:, 1]) * h / 2
        centre = p_px + dist[:, None] * d
        boxes = np.hstack([centre - [w / 2, h / 2], centre + [w / 2, h / 2]])
        deviation = np.abs((angle - away + np.pi) % (2 * np.pi) - np.pi)
        cost = 40.0 * ring + 15.0 * deviation
        outside = (np.maximum(0, inner[0] - boxes[:, 0]) + np.maximum(0, boxes[:, 2] - inner[2]) +
                   np.maximum(0, inner[1] - boxes[:, 1]) + np.maximum(0, boxes[:, 3] - inner[3]))
        cost += 1e5 * outside
        for q in placed:
            ow = np.minimum(boxes[:, 2], q[2]) - np.maximum(boxes[:, 0], q[0])
            oh = np.minimum(boxes[:, 3], q[3]) - np.maximum(boxes[:, 1], q[1])
            hit = (ow > 0) & (oh > 0)
            cost += np.where(hit, 1e4 + 100 * ow * oh, 0.0)
        cost += 60.0 * _clip_lengths(heavy, boxes) + 6.0 * _clip_lengths(light, boxes)
        for cc, rr in discs:
            nx = np.clip(cc[0], boxes[:, 0], boxes[:, 2])
            ny = np.clip(cc[1], boxes[:, 1], boxes[:, 3])
            cost += np.where(np.hypot(nx - cc[0], ny - cc[1]) < rr + 1, 3000.0, 0.0)
        for poly in areas:
            cost += np.where(_inside(poly, centre), 800.0, 0.0)
        k = int(np.argmin(cost))
        placed = np.vstack([placed, boxes[k]])
        offset = centre[k] - p_px
        text.set_position((offset[0] / scale, offset[1] / scale))


def _pin_points(sc: _Scene) -> set[str]:
    return {name for name, p in sc.points.items() if any(np.allclose(p, q) for _, q in sc.pins)}


def _away(sc: _Scene, name: str, p: np.ndarray, centre_all: np.ndarray) -> float:
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
