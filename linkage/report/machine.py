"""Pictures of a machine's dynamics, as the course manuals draw them for a scheme with a
``[dynamics]`` section (docs/methods.md, "Mertsalov's method" and "The equation of motion").

- :func:`plot_moments_and_work` -- reduced moments of the resistance and the constant driving
  moment ``M_d``; the work ``A_c``, ``A_d`` and the energy change ``ΔT = A_d + A_c`` by the course
  method's trapezoid;
- :func:`plot_energy_inertia` -- the energy–inertia diagram (Wittenbauer): ``ΔT`` against ``I''``;
- :func:`plot_flywheel_energy` -- ``ΔT' = ΔT − T''`` with its swing ``ΔT'_ab`` and the flywheel;
- :func:`plot_speed_two_ways` -- ``ω(φ)`` and ``ε(φ)`` by the course method and by the equation
  of motion with the same constant inertia and a constant driving moment (its periodic steady
  state);
- :func:`plot_startup` -- the start-up with the scheme's motor from several initial speeds.

The first four take a course-method :class:`~linkage.dynamics.pipeline.DynamicsReport`
(``run_dynamics(mech, "course")``); their angle axis is ``phi_deg``, the crank angle travelled
from the cycle's start (0 .. 360), with the table positions numbered and the output's extreme
positions marked (:func:`~linkage.report.plots.extreme_marks`). Reduced moments refer to
``psi = s·phi`` (positive when they drive, docs/conventions.md). Every function returns a
matplotlib ``Figure`` about 7.5 in wide; it needs the ``plot`` extra.

>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import linkage
>>> from linkage.dynamics.pipeline import run_dynamics
>>> fig = plot_flywheel_energy(run_dynamics(linkage.load("course_slider_crank"), compare=False))
>>> fig.axes[0].get_ylabel().split(",")[-1].strip()
'J'
>>> matplotlib.pyplot.close(fig)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..dynamics.cycle import LawOfMotion, exact_method
from ..dynamics.equation import StartupStall, simulate, steady_state
from ..dynamics.motors import starting_moment
from ..dynamics.pipeline import DynamicsReport
from ..dynamics.reduced import reduced_characteristics
from ..dynamics.spec import DynamicsSpec
from ..errors import InputError
from ..kinematics.motion import table_positions_deg
from ..model.mechanism import Mechanism
from ..model.scheme import section_of
from .diagrams import extreme_marks, figure_legend, finish_panels, plot_columns, wrapped_label
from .style import CURVE_COLOURS, FONT, MARKERS, SMALL, new_figure, pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "plot_energy_inertia",
    "plot_flywheel_energy",
    "plot_moments_and_work",
    "plot_speed_two_ways",
    "plot_startup",
]

#: figure width, inches: readable on an A4 page (landscape text width or a full portrait width)
FIGURE_WIDTH = 7.5

#: the equation of motion's grid of the reduced moment (steady_state's default ``samples``)
ODE_SAMPLES = 720

#: default initial speeds of the start-up, in units of the declared |omega_m|
START_FRACTIONS = (0.0, 0.5, 1.0, 1.5)


# ----------------------------------------------------------------------------------------------
# inputs
# ----------------------------------------------------------------------------------------------


def _declared(mech: Mechanism, picture: str) -> DynamicsSpec:
    """The scheme's ``[dynamics]`` inputs; InputError naming the scheme and the ``picture`` when it
    declares none."""
    spec = section_of(mech, "dynamics")
    if spec is None:
        raise InputError(f"scheme '{mech.name}' declares no [dynamics] section: no {picture}")
    return spec


def _course_law(report: DynamicsReport, picture: str) -> LawOfMotion:
    """The course method's law of motion of ``report``; InputError when the scheme has no
    ``[dynamics]`` section or the report is of another method (no trapezoid table)."""
    _declared(report.mechanism, picture)
    law = report.law
    if law.method != "course" or "energy_flywheel" not in law.details:
        raise InputError(f"scheme '{report.mechanism.name}': the {picture} draws the course method's (Mertsalov's) "
                         f"table, but the report is of the {law.method!r} method: make it with "
                         "run_dynamics(mech, 'course')")
    return law


def _mean_speed_and_delta(law: LawOfMotion) -> tuple[float, float]:
    """The mean speed ``omega_m`` (rad/s, signed) and the target ``delta`` the course method was run
    with, from its own formulas (docs/methods.md, "Mertsalov's method", steps 4-5):
    ``w_i² = w_m² + 2 (ΔT'_i − (max ΔT' + min ΔT')/2) / C`` gives ``w_m`` at every position (their
    mean is taken), and ``I' = ΔT'_ab / (δ w_m²)`` gives ``δ``. So the pictures show the numbers of
    the report even when ``run_dynamics`` overrode the declared ones."""
    energy = law.details["energy_flywheel"]
    middle = (np.max(energy) + np.min(energy)) / 2
    w2 = np.abs(law.omega) ** 2 - 2 * (energy - middle) / law.constant_inertia
    wm2 = float(np.mean(w2))
    delta = law.details["energy_swing"] / (law.required_constant_inertia * wm2)
    return law.reduced.rotation * math.sqrt(wm2), float(delta)


def _table(law: LawOfMotion) -> dict[str, np.ndarray]:
    """``i`` (from 1) and ``phi_deg`` (0 .. 360) of the law's table positions."""
    return {"i": np.arange(1, len(law.phi) + 1), "phi_deg": table_positions_deg(law.phi)}


def _marks(mech: Mechanism, phi: np.ndarray) -> list[tuple[float, str]]:
    """The output's extreme positions on the table's ``phi_deg`` axis (none without an output)."""
    return extreme_marks(mech, phi) if mech.output is not None else []


def _relabel(ax, labels: Mapping[str, str], style: Mapping[str, object] | None = None) -> None:
    """Give the curves :func:`plot_columns` drew for the keys of ``labels`` (gid ``positions:key``)
    their legend text in words, and optionally a line style."""
    for line in ax.lines:
        key = str(line.get_gid() or "").partition(":")[2]
        if key in labels and line.get_label() and not line.get_label().startswith("_"):
            line.set_label(labels[key])
            line.set(**(style or {}))


def _text_panel(fig, ax, lines: Sequence[str]) -> None:
    """``lines`` of text in an axes of their own, under the diagram (never over the curves)."""
    ax.axis("off")
    ax.text(0.0, 1.0, "\n".join(lines), transform=ax.transAxes, ha="left", va="top", fontsize=FONT,
            linespacing=1.5, gid="result-text")


def _signed(x: float, digits: int = 4) -> str:
    """A number with a typographic minus."""
    return f"{x:.{digits}g}".replace("-", "−")


# ----------------------------------------------------------------------------------------------
# 1. moments and work
# ----------------------------------------------------------------------------------------------


def plot_moments_and_work(report: DynamicsReport) -> Figure:
    """Reduced moments and the work of the cycle, by the course method's trapezoid.

    Top panel: the reduced moment of the resistance and gravity ``M_c`` (and of declared driving
    loads, when there are any), N·m, positive when it drives, with the constant driving moment
    ``M_d`` that balances the cycle. Bottom panel: the work of the loads
    ``A_c,i = Σ (M_red,k + M_red,k+1)/2·Δψ``, of the driving moment ``A_d = M_d·ψ`` and the change
    of kinetic energy ``ΔT = A_d + A_c`` (J), at the table positions.

    Parameters
    ----------
    report : DynamicsReport
        ``run_dynamics(mech, "course")`` of a scheme with a ``[dynamics]`` section.

    Returns
    -------
    matplotlib Figure
        Two panels over ``phi_deg`` (deg), the positions numbered, a legend in words below.

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section, or the report is not of the course method.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    law = _course_law(report, "diagram of moments and work")
    mech, red, details = report.mechanism, law.reduced, law.details
    n = len(law.phi) - 1
    psi = np.arange(n + 1) * 2 * np.pi / n
    md = float(law.driving_moment)
    columns = {**report.columns(), "A_c": details["work_resistance"], "A_d": md * psi,
               "dT": details["energy_change"]}
    marks = _marks(mech, law.phi)
    fig = new_figure(FIGURE_WIDTH, 7.6)
    axes = fig.subplots(2, 1, sharex=True)
    driving = bool(np.any(red.moment_driving != 0))
    moments = ["reduced_moment_resistance"] + (["reduced_moment_driving"] if driving else [])
    plot_columns(columns, moments, axes[0], mechanism=mech, marks=marks, mean_moment=md,
                 mean_label=f"constant driving moment $M_d$ = {_signed(md)} N·m (balances the cycle)",
                 legend=False)
    axes[0].set_ylabel(wrapped_label("reduced moments $M_c$, $M_d$, N·m", axes[0]), fontsize=FONT)
    plot_columns(columns, ["A_c", "A_d", "dT"], axes[1], mechanism=mech, marks=marks, numbers=False,
                 legend=False)
    loads = "the declared loads" if driving else "the resistance and gravity"
    _relabel(axes[1], {"A_c": f"work of {loads} $A_c$ (J, trapezoid over the table positions)",
                       "A_d": r"work of the driving moment $A_d = M_d\,\psi$ (J)",
                       "dT": r"change of kinetic energy $\Delta T = A_d + A_c$ (J)"})
    axes[1].set_ylabel(wrapped_label(r"work $A_c$, $A_d$ and energy change $\Delta T$, J", axes[1]), fontsize=FONT)
    finish_panels(axes)
    figure_legend(fig, axes)
    return fig


# ----------------------------------------------------------------------------------------------
# 2. energy-inertia diagram
# ----------------------------------------------------------------------------------------------


def _label_step(count: int, room: int = 24) -> int:
    """Label every k-th position so that at most about ``room`` numbers are written."""
    return max(1, math.ceil(count / room))


def _outward(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Unit directions (in the axes' scaled units) away from a closed curve at each of its points:
    the normal of the chord between the neighbours, turned away from the curve's centre."""
    sx, sy = np.ptp(x) or 1.0, np.ptp(y) or 1.0
    u, v = (x - np.mean(x)) / sx, (y - np.mean(y)) / sy
    du, dv = np.roll(u, -1) - np.roll(u, 1), np.roll(v, -1) - np.roll(v, 1)
    normal = np.stack([dv, -du], axis=1)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    away = np.stack([u, v], axis=1)
    flip = np.einsum("ni,ni->n", normal, away) < 0
    normal[flip] *= -1
    return normal


def plot_energy_inertia(report: DynamicsReport) -> Figure:
    """The energy–inertia diagram (Wittenbauer): ``ΔT`` against ``I''`` over the cycle.

    The change of kinetic energy ``ΔT = A_d + A_c`` (J, vertical) against the variable part of
    the reduced moment of inertia ``I''`` (kg·m², horizontal) at the table positions: a closed
    curve (position n+1 is position 1), the positions numbered along it, the output's extreme
    positions marked. ``I = I_0 + I''`` with the constant ``I_0`` written on the figure.

    Parameters
    ----------
    report : DynamicsReport
        ``run_dynamics(mech, "course")`` of a scheme with a ``[dynamics]`` section.

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section, or the report is not of the course method.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    law = _course_law(report, "energy–inertia diagram")
    mech, red = report.mechanism, law.reduced
    x = np.asarray(red.inertia_variable, dtype=float)
    y = np.asarray(law.details["energy_change"], dtype=float)
    n = len(x) - 1
    fig = new_figure(FIGURE_WIDTH, 6.4)
    ax = fig.add_subplot()
    ax.plot(x, y, "-", color=CURVE_COLOURS[0], lw=1.6, marker=MARKERS[0], ms=5 if n <= 40 else 3.5, mfc="white",
            mew=1.3, zorder=3, label=r"$\Delta T$ against $I''$ at the table positions", gid="energy-inertia")
    phi_deg = table_positions_deg(law.phi)
    for k, (at, text) in enumerate(dict.fromkeys(_marks(mech, law.phi))):
        if at >= 360.0 - 1e-9 and mech.input_range is None:
            continue  # the end of the turn is its start on this closed curve
        ax.plot(np.interp(at, phi_deg, x), np.interp(at, phi_deg, y), ls="none", marker="D", ms=8,
                color=CURVE_COLOURS[1 + k % (len(CURVE_COLOURS) - 1)], zorder=5,
                label=f"extreme position of the output: {text}", gid="extreme-position")
    directions = _outward(x[:-1], y[:-1])
    for i in range(0, n, _label_step(n)):
        dx, dy = (16 if i == 0 else 11) * directions[i]
        ax.annotate(f"1 = {n + 1}" if i == 0 else str(i + 1), (x[i], y[i]), xytext=(dx, dy), textcoords="offset points", ha="center",
                    va="center", fontsize=SMALL, gid="position-number")
    ax.margins(0.08)
    ax.axhline(0.0, color="0.4", lw=0.8, zorder=1)
    ax.grid(True, alpha=0.35)
    ax.tick_params(labelsize=SMALL)
    ax.set_xlabel(f"variable part of the reduced moment of inertia $I''$, kg·m²  "
                  f"($I = I_0 + I''$, $I_0$ = {red.inertia_constant:.4g} kg·m²)", fontsize=FONT)
    ax.set_ylabel(wrapped_label(r"change of kinetic energy $\Delta T = A_d + A_c$, J", ax), fontsize=FONT)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=SMALL, frameon=False)
    return fig


# ----------------------------------------------------------------------------------------------
# 3. the energy of the constant-inertia parts and the flywheel
# ----------------------------------------------------------------------------------------------


def _flywheel_words(law: LawOfMotion, delta: float, wm: float) -> list[str]:
    """The flywheel result in words and numbers."""
    swing, required, i0 = law.details["energy_swing"], law.required_constant_inertia, law.reduced.inertia_constant
    first = (f"required constant inertia $I' = \\Delta T'_{{ab}} / (\\delta\\,\\omega_m^2)$ with δ = {delta:.4g}, "
             f"$|\\omega_m|$ = {wm:.4g} rad/s:")
    numbers = f"    $I'$ = {swing:.4g} J / ({delta:.4g} × {wm:.4g}² rad²/s²) = {required:.4g} kg·m²"
    if law.flywheel_inertia is not None:
        second = (f"flywheel $I_{{fw}} = I' - I_0$ = {required:.4g} − {i0:.4g} = {law.flywheel_inertia:.4g} kg·m² "
                  "on the crank shaft")
    else:
        second = (f"no flywheel needed: $I'$ ≤ $I_0$ = {i0:.4g} kg·m², the machine runs with "
                  f"δ = $\\Delta T'_{{ab}} / (I_0\\,\\omega_m^2)$ = {law.delta_actual:.4g}")
    return [first, numbers, second]


def _mark_extreme_energy(ax, phi: np.ndarray, energy: np.ndarray, k: int, which: str) -> None:
    """The level of the ``which`` ("max" or "min") of ``ΔT'`` (row ``k``) as a dotted line, its
    positions (ties included: position n+1 repeats position 1) as dots, and their numbers."""
    level = energy[k]
    ties = np.flatnonzero(np.abs(energy - level) <= 1e-12 * max(float(np.ptp(energy)), abs(level), 1e-300))
    ax.axhline(level, color="0.35", ls=":", lw=1.0, gid=f"level-{which}")
    ax.plot(phi[ties], energy[ties], ls="none", marker="o", ms=7, color=CURVE_COLOURS[1], zorder=4, clip_on=False,
            gid=f"energy-{which}")
    where = ", ".join(str(i + 1) for i in ties)
    right = phi[k] > 0.8 * phi[-1]
    up = which == "max"
    ax.annotate(f"{which} $\\Delta T'$ (position{'s' if len(ties) > 1 else ''} {where})", (phi[k], level),
                xytext=(-6 if right else 6, 6 if up else -6), textcoords="offset points", ha="right" if right else "left",
                va="bottom" if up else "top", fontsize=SMALL, gid=f"text-{which}")


def plot_flywheel_energy(report: DynamicsReport) -> Figure:
    """The energy of the constant-inertia parts ``ΔT' = ΔT − T''`` and Mertsalov's flywheel.

    ``ΔT'`` (J) against the crank angle at the table positions, its maximum and minimum marked,
    the swing ``ΔT'_ab = max ΔT' − min ΔT'`` drawn as a dimension (an arrow, gid ``swing``, from
    the minimum to the maximum), and the result written under the diagram:
    ``I' = ΔT'_ab / (δ·ω_m²)`` and the flywheel ``I_fw = I' − I_0``, or "no flywheel needed".
    ``T'' = I''·ω_m²/2`` is the energy of the links with variable inertia at the mean speed.

    Parameters
    ----------
    report : DynamicsReport
        ``run_dynamics(mech, "course")`` of a scheme with a ``[dynamics]`` section.

    Returns
    -------
    matplotlib Figure

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section, or the report is not of the course method.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    law = _course_law(report, "diagram of the flywheel energy")
    mech = report.mechanism
    omega_m, delta = _mean_speed_and_delta(law)
    energy = np.asarray(law.details["energy_flywheel"], dtype=float)
    columns = {**_table(law), "dT1": energy}
    fig = new_figure(FIGURE_WIDTH, 5.9)
    ax, text_ax = fig.subplots(2, 1, height_ratios=[4.8, 1])
    plot_columns(columns, ["dT1"], ax, mechanism=mech, marks=_marks(mech, law.phi), legend=False)
    _relabel(ax, {"dT1": r"energy change of the constant-inertia parts $\Delta T' = \Delta T - T''$ (J)"})
    ax.set_ylabel(wrapped_label(r"energy change $\Delta T' = \Delta T - T''$, J", ax), fontsize=FONT)
    phi = columns["phi_deg"]
    high, low = int(np.argmax(energy)), int(np.argmin(energy))
    for k, which in ((high, "max"), (low, "min")):
        _mark_extreme_energy(ax, phi, energy, k, which)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo - 0.08 * (hi - lo), hi)  # room for the text under the minimum
    x = (phi[high] + phi[low]) / 2
    ax.annotate("", xy=(x, energy[high]), xytext=(x, energy[low]), gid="swing",
                arrowprops={"arrowstyle": "<|-|>", "color": "black", "lw": 1.2, "shrinkA": 0, "shrinkB": 0})
    swing = law.details["energy_swing"]
    ax.annotate(f"$\\Delta T'_{{ab}}$ = {swing:.4g} J", (x, (energy[high] + energy[low]) / 2), xytext=(5, 0),
                textcoords="offset points", ha="left", va="center", fontsize=FONT, gid="swing-text",
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.9})
    _text_panel(fig, text_ax, _flywheel_words(law, delta, abs(omega_m)))
    return fig


# ----------------------------------------------------------------------------------------------
# 4. speed and acceleration two ways
# ----------------------------------------------------------------------------------------------


def _steady_with_constant_moment(mech: Mechanism, law: LawOfMotion, omega_m: float,
                                 delta: float) -> tuple[LawOfMotion, int]:
    """The periodic steady state of the equation of motion with the course law's constant
    inertia and a constant driving moment (no motor: the moment that balances the cycle on the
    equation's grid), on a table ``k`` times finer than the law's, whose every k-th row is a
    table position; and ``k``. The finer table uses the same grid of the reduced moment as the
    law's own (``n·⌈720/n⌉`` steps)."""
    n = len(law.phi) - 1
    fine = n * math.ceil(ODE_SAMPLES / n)
    spec = replace(_declared(mech, "diagram of the speed"), mean_speed=omega_m, delta=delta, positions=n,
                   motor=None)
    ode = steady_state(mech, spec, constant_inertia=law.constant_inertia, positions=fine, samples=ODE_SAMPLES)
    return ode, fine // n


def plot_speed_two_ways(report: DynamicsReport) -> Figure:
    """``ω(φ)`` and ``ε(φ)`` of the crank by the course method and by the equation of motion.

    Markers: the course method (Mertsalov) at the table positions. Fine curve: the periodic
    steady state of the equation of motion ``I(ψ)·ψ̈ + ½·(dI/dψ)·ψ̇² = M_d + M_red(ψ)`` with the
    same constant inertia (the law's ``constant_inertia``) and a constant driving moment ``M_d``
    that balances the cycle on the equation's grid (:func:`~linkage.dynamics.equation.steady_state` with no
    motor; its ``M_d`` differs from the course method's where a load acts between table
    positions: both are written). The mean speed ``ω_m`` and the band ``ω_m·(1 ± δ/2)`` of the
    target δ are drawn on the speed panel; the δ of each solution is written in the legend.
    Speeds are signed (counter-clockwise positive), as in the tables.

    Parameters
    ----------
    report : DynamicsReport
        ``run_dynamics(mech, "course")`` of a scheme with a ``[dynamics]`` section.

    Returns
    -------
    matplotlib Figure
        Two panels (ω in rad/s, ε in rad/s²) over ``phi_deg``; gids ``curve:omega-ode`` and
        ``curve:eps-ode`` for the equation's curves, ``positions:omega`` and ``positions:eps``
        for the course method's markers.

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section, or the report is not of the course method.
    DynamicsError
        The equation of motion has no periodic steady state with that inertia.
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    law = _course_law(report, "diagram of the speed")
    mech = report.mechanism
    omega_m, delta = _mean_speed_and_delta(law)
    ode, _ = _steady_with_constant_moment(mech, law, omega_m, delta)
    columns = {**_table(law), "omega": law.omega, "eps": law.eps}
    fine_deg = table_positions_deg(ode.phi)
    marks = _marks(mech, law.phi)
    fig = new_figure(FIGURE_WIDTH, 8.2)
    axes = fig.subplots(2, 1, sharex=True)
    sense = "clockwise: ω < 0" if omega_m < 0 else "counter-clockwise: ω > 0"
    ode_label = (f"equation of motion, periodic steady state (δ = {ode.delta_actual:.3g}): the same constant inertia "
                 f"{law.constant_inertia:.4g} kg·m²,\nconstant $M_d$ = {_signed(ode.driving_moment)} N·m that "
                 f"balances the cycle on a fine grid ({len(ode.phi) - 1} steps)")
    course_label = (f"course method (Mertsalov) at the table positions (δ = {delta:.3g}): "
                    f"$M_d$ = {_signed(law.driving_moment)} N·m from the trapezoid")
    for k, (ax, name, values) in enumerate(zip(axes, ("omega", "eps"), (ode.omega, ode.eps))):
        ax.plot(fine_deg, values, "-", color=CURVE_COLOURS[1], lw=1.4, label=ode_label, gid=f"curve:{name}-ode")
        if name == "omega":
            ax.axhline(omega_m, color="black", ls="--", lw=1.1, gid="mean-speed",
                       label=f"mean speed $\\omega_m$ = {_signed(omega_m)} rad/s ({sense})")
            for side in (-1, 1):
                ax.axhline(omega_m * (1 + side * delta / 2), color="0.45", ls="-.", lw=0.9, gid="delta-band",
                           label=f"$\\omega_m\\,(1 \\pm \\delta/2)$, target δ = {delta:.4g}" if side > 0 else None)
        plot_columns(columns, [name], ax, mechanism=mech, marks=marks, numbers=k == 0, legend=False)
        _relabel(ax, {name: course_label}, {"color": CURVE_COLOURS[0], "ls": ":", "lw": 1.0})
    finish_panels(axes)
    figure_legend(fig, axes)
    return fig


# ----------------------------------------------------------------------------------------------
# 5. start-up
# ----------------------------------------------------------------------------------------------


def _startup_inertia(mech: Mechanism, spec: DynamicsSpec) -> tuple[float, str]:
    """The constant inertia of the start-up (kg·m²) and where it comes from: the flywheel sized by
    the exact method for the declared δ (as ``linkage dynamics --method ode --transient``), else
    the declared constant inertia with the crank's own."""
    if spec.delta is not None:
        constant = exact_method(mech, spec).constant_inertia
        return constant, f"flywheel sized by the exact method for δ = {spec.delta:.4g}"
    red = reduced_characteristics(mech, [0.0], spec.rotation, extra_inertia=spec.constant_inertia)
    return red.inertia_constant, "as declared, no flywheel"


def _start_speeds(spec: DynamicsSpec, initial_speeds: Sequence[float] | None) -> tuple[list[float], list[str]]:
    """The initial speeds |ω| (rad/s) of the start-up curves and notes: by default 0 (when the motor
    has a starting torque), 0.5, 1 and 1.5 times the declared |ω_m|."""
    if initial_speeds is not None:
        speeds = [float(w) for w in initial_speeds]
        if not speeds:
            raise InputError("initial_speeds: give at least one initial speed |omega| (rad/s)")
        return speeds, []
    wm = abs(spec.mean_speed)
    starting = starting_moment(spec.motor)
    speeds = [f * wm for f in START_FRACTIONS if f > 0 or starting > 0]
    notes = [] if starting > 0 else [f"no start from rest: the motor's moment at rest is {starting:.3g} N·m"]
    return speeds, notes


def plot_startup(mech: Mechanism, initial_speeds: Sequence[float] | None = None, *, cycles: int | None = None,
                 constant_inertia: float | None = None, notes: list[str] | None = None) -> Figure:
    """The start-up of the machine with its motor: ``|ω|`` against the crank angle travelled.

    One curve per initial speed, from the equation of motion with the scheme's motor
    (:func:`~linkage.dynamics.equation.simulate`; a start from rest integrates its first degree in time),
    and the mean speed of the periodic steady state with that motor
    (:func:`~linkage.dynamics.equation.steady_state`) that every start-up approaches; the declared mean
    speed is drawn for comparison.

    Parameters
    ----------
    mech : Mechanism
        A scheme with a ``[dynamics]`` section that declares a motor (``[dynamics.motor]``).
    initial_speeds : sequence of float, optional
        Initial |ω| of the curves, rad/s (0: from rest, which needs a motor with a starting
        torque). Default: 0 (when the motor has a starting torque), 0.5, 1 and 1.5 times the
        declared |ω_m|.
    cycles : int, optional
        Turns of the crank to integrate (default: the declared ``cycles``).
    constant_inertia : float, optional
        Constant inertia at the crank, kg·m² (default: the flywheel sized by the exact method for
        the declared δ, as ``linkage dynamics --method ode --transient``; without δ the declared
        one).
    notes : list of str, optional
        A start-up that stalls (ω → 0) is drawn up to the stall, marked with a cross, and a note
        saying where, when and why (:meth:`~linkage.dynamics.equation.Stall.words`) is appended here.

    Returns
    -------
    matplotlib Figure
        x: the crank angle travelled from position 1, turns; y: |ω|, rad/s. Curves have gids
        ``startup:<k>`` in the order of the speeds, the steady mean speed ``steady-mean-speed``,
        the cross at a stall ``stall:<k>``.

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section or no motor (with a constant driving moment
        that balances the cycle every speed is its own steady state: there is no start-up), no
        initial speeds, or an argument out of range.
    DynamicsError
        The machine runs away, or has no steady state with that motor (a start-up that stalls is
        drawn up to the stall, with a note).
    PlotExtraMissing
        matplotlib is not installed.
    """
    pyplot()
    spec = _declared(mech, "start-up diagram")
    if spec.motor is None:
        raise InputError(f"scheme '{mech.name}' declares no motor ([dynamics.motor]): with a constant driving moment "
                         "that balances the cycle every start speed is its own steady state, so there is no "
                         "start-up to draw: no start-up diagram")
    speeds, said = _start_speeds(spec, initial_speeds)
    if constant_inertia is None:
        constant, origin = _startup_inertia(mech, spec)
    else:
        constant, origin = float(constant_inertia), "given"
    turns = cycles if cycles is not None else spec.cycles
    steady = abs(steady_state(mech, spec, constant_inertia=constant).details["mean_speed"])
    fig = new_figure(FIGURE_WIDTH, 5.6)
    ax = fig.add_subplot()
    for k, w0 in enumerate(speeds):
        colour = CURVE_COLOURS[k % len(CURVE_COLOURS)]
        start = "from rest" if w0 == 0 else f"from |ω| = {w0:.3g} rad/s"
        try:
            run, ending = simulate(mech, spec, initial_speed=w0, cycles=turns, constant_inertia=constant), ""
        except StartupStall as stalled:
            run, stall = stalled.transient, stalled.stall
            ending = f": stalls (ω → 0) at ψ = {stall.degrees:.1f}° of turn {stall.turn} after {stall.t:.3g} s"
            ax.plot([stall.psi / (2 * np.pi)], [0.0], "x", ms=9, mew=2, color=colour, clip_on=False, zorder=5,
                    gid=f"stall:{k}")
            if notes is not None:
                notes.append(f"start-up diagram: {stall.words()}")
        ax.plot(run.psi / (2 * np.pi), np.abs(run.omega), "-", lw=1.5, color=colour,
                label=f"start-up {start}{ending}", gid=f"startup:{k}")
    ax.axhline(steady, color="black", ls="--", lw=1.2, gid="steady-mean-speed",
               label=f"mean speed of the steady state with this motor: {steady:.4g} rad/s")
    ax.axhline(abs(spec.mean_speed), color="0.5", ls=":", lw=1.2, gid="declared-mean-speed",
               label=f"declared mean speed $|\\omega_m|$ = {abs(spec.mean_speed):.4g} rad/s")
    _style_turns(ax, turns)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("crank angle travelled from position 1, turns (360° each)", fontsize=FONT)
    ax.set_ylabel(wrapped_label("angular speed of the crank $|\\omega|$ (magnitude), rad/s", ax), fontsize=FONT)
    ax.set_title(f"start-up of '{mech.name}' with its motor; constant inertia at the crank {constant:.4g} kg·m² "
                 f"({origin})" + "".join(f"; {note}" for note in said), fontsize=SMALL, loc="left", wrap=True)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=SMALL, frameon=False)
    return fig


def _style_turns(ax, turns: int) -> None:
    """x axis over ``turns`` whole turns, a major tick at each (thinned when many), grid."""
    from matplotlib.ticker import AutoMinorLocator, MaxNLocator

    ax.set_xlim(0, turns)
    ax.xaxis.set_major_locator(MaxNLocator(nbins=min(turns, 12), integer=True))
    ax.xaxis.set_minor_locator(AutoMinorLocator())
    ax.tick_params(labelsize=SMALL)
    ax.grid(True, which="major", alpha=0.35)
