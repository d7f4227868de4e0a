"""The course project's dynamics sheet: the diagrams of the machine's dynamics and the flywheel.

:func:`dynamics_sheet` draws, from the course pipeline (:func:`linkage.dynamics.run_dynamics`,
Mertsalov's method on the table positions, as ``linkage dynamics`` computes it):

- stacked on the left on one ψ axis (ψ the angle turned from position 1 in the direction of
  rotation): the reduced moment M_red(ψ) with the constant driving moment M_d; the works
  A_c(ψ) and A_d(ψ); the change of kinetic energy ΔT(ψ) = A_d + A_c; the reduced moment of inertia
  I_red(ψ) = I_0 + I''(ψ) (its axis at I_0); the crank's angular velocity ω(ψ);
- on the right the energy–inertia (Wittenbauer) diagram ΔT against I'' with the tangents at the
  course's angles ψ_max and ψ_min and the segment kl they cut on the ΔT axis
  (:func:`~.flywheel.wittenbauer_tangents`), the constant inertia ``I' = μ_T·kl / (ω_m²·δ)`` they
  give next to Mertsalov's;
- below it the useful resistance P(s) over the stroke (the scheme's load diagram), the scales,
  the method in words, and the flywheel sized as a rim (:func:`~.flywheel.rim_for_inertia`)
  with a sketch of its cross-section, above the title block.

Every diagram is drawn at a standard scale (1, 2, 2.5, 4, 5 x 10^n per mm) stated in the scales
table; a quantity drawn twice (ΔT, I'') has one scale on the sheet.
"""

from __future__ import annotations

import math

import numpy as np

from ...dynamics import run_dynamics
from ...dynamics.spec import dynamics_of
from ...errors import InputError
from ...kinematics.extremes import extreme_positions
from ...kinematics.motion import analyze
from ...kinetostatics.loads import CycleTable, StrokeDiagram, loads_of
from ...model.mechanism import Mechanism
from ...model.scheme import section_of
from .flywheel import (
    RIM_HEIGHT_RATIO,
    RIM_WIDTH_RATIO,
    STEEL_DENSITY,
    rim_for_inertia,
    tangent_angles,
    wittenbauer_tangents,
)
from .frame import TitleInfo, blank_sheet, scales_table, table
from ...report.plan_drawings import nice_scale
from .kinematics_parts import fitting_scale
from .model import Arrow, Circle, Drawing, Line, Scale, Text, standard_scale

__all__ = ["dynamics_sheet", "useful_resistance"]

#: the sheet's number among the project's three
SHEET_NUMBER, SHEET_TOTAL = 3, 3


def dynamics_sheet(mech: Mechanism, paper: str = "A1", title: TitleInfo = TitleInfo(), *,
                   density: float = STEEL_DENSITY, width_ratio: float = RIM_WIDTH_RATIO,
                   height_ratio: float = RIM_HEIGHT_RATIO) -> Drawing:
    """The dynamics sheet of a course project (see the module docstring for what it shows).

    Parameters
    ----------
    mech : Mechanism
        A machine with a ``[dynamics]`` section (mean speed and δ) whose input turns fully.
    paper : {"A1", "A2", "A3"}
        The paper (landscape).
    title : TitleInfo
        The title block's names.
    density, width_ratio, height_ratio : float
        The flywheel rim's material (kg/m³, default steel 7800) and its proportions
        ψ_b = b/D (default 0.2) and ψ_h = h/D (default 0.15).

    Returns
    -------
    Drawing

    Raises
    ------
    InputError
        The scheme declares no ``[dynamics]`` section, or no ``delta`` in it (named in the message).
    LinkageError
        What the dynamics pipeline raises (a partial input range, an undetermined speed ...).
    """
    if paper not in ("A1", "A2", "A3"):
        raise InputError(f"the dynamics sheet is laid out for A1, A2 or A3, got paper {paper!r}")
    if section_of(mech, "dynamics") is None:
        raise InputError(f"mechanism '{mech.name}': the dynamics sheet needs the scheme's [dynamics] section "
                         "(mean_speed or mean_rpm, delta, positions, inertia_0): add [dynamics]")
    spec = dynamics_of(mech)
    if spec.delta is None:
        raise InputError(f"mechanism '{mech.name}': the dynamics sheet sizes the flywheel for the coefficient of "
                         "speed fluctuation: add delta to [dynamics]")
    law = run_dynamics(mech, "course", compare=False).law
    data = _SheetData(mech, law, spec.delta)
    rim = None if law.flywheel_inertia is None else rim_for_inertia(law.flywheel_inertia, density, width_ratio,
                                                                    height_ratio)
    drawing, free = blank_sheet(paper, title, "Dynamics of the machine", SHEET_NUMBER, SHEET_TOTAL)
    layout = _Layout(free, drawing.paper)
    scales = _choose_scales(drawing, data, layout)
    _psi_panels(drawing, data, scales, layout)
    _energy_inertia_panel(drawing, data, scales, layout.witt, layout.text, layout.heading)
    _resistance_panel(drawing, mech, data, layout.resistance, layout.text, layout.heading)
    _flywheel_panel(drawing, data, rim, layout.flywheel, layout.text, layout.heading)
    _notes(drawing, data, layout.notes, layout.text)
    scales_table(drawing, (layout.scales[0], layout.scales[3]), height=layout.text)
    return drawing


# ----------------------------------------------------------------------------------------------
# the numbers
# ----------------------------------------------------------------------------------------------


class _SheetData:
    """The course method's arrays over ψ at the table positions, and the tangents."""

    def __init__(self, mech: Mechanism, law, delta: float):
        red = law.reduced
        n = len(law.phi) - 1
        self.mech, self.law, self.delta, self.n = mech, law, float(delta), n
        self.psi = np.arange(n + 1) * 2 * np.pi / n
        self.moment = red.moment                           # M_red (the declared loads), N m
        self.driving = float(law.driving_moment)           # M_d, N m
        self.work_resistance = law.details["work_resistance"]  # A_c, J
        self.work_driving = self.driving * self.psi        # A_d, J
        self.energy = law.details["energy_change"]         # ΔT, J
        self.inertia_constant = float(red.inertia_constant)  # I_0
        self.inertia_variable = red.inertia_variable       # I''
        self.omega = np.abs(law.omega)                     # rad/s
        self.mean_speed = abs(float(dynamics_of(mech).mean_speed))   # ω_m, rad/s
        self.tangents = wittenbauer_tangents(self.energy, self.inertia_variable, self.mean_speed, self.delta)


class _Layout:
    """The sheet's parts in the frame's free box (x0, y0, x1, y1), in proportion to the paper.

    A1: the ψ diagrams on the left half; on the right the energy–inertia diagram above, the
    useful resistance and the flywheel below it, the scales and the notes left of the title block.
    A2 and A3 (no room left of the title block): the scales and the notes under the ψ diagrams,
    the useful resistance and the flywheel side by side above the title block. Text heights
    (headings / text): A1 5 / 3.5 mm, A2 and A3 3.5 / 2.5 mm.
    """

    def __init__(self, free, paper: str):
        x0, y0, x1, y1 = free
        self.compact = paper != "A1"
        self.heading = 3.5 if self.compact else 5.0
        self.text = 2.5 if self.compact else 3.5
        h = self.text
        self.pad = 2.2 * h + 12.0 + 1.6 * self.heading   # a ψ panel's numbers, arrow heads and caption
        width, height = x1 - x0, y1 - y0
        split = x0 + 0.50 * width                          # left: the ψ diagrams
        block_x = x1 - 185.0                               # the title block's left edge
        block_top = y0 + 55.0 + 4.0                        # room above the title block
        if not self.compact:
            self.left = (x0, y0, split, y1)
            low = y0 + 0.47 * height                       # the Wittenbauer diagram above this
            self.witt = (split + 4, low, x1, y1)
            self.flywheel = (block_x, block_top + 1.0, x1, low - 4)
            self.resistance = (split + 4, y0 + 0.22 * height, block_x - 4, low - 4)
            self.scales = (split + 4, y0, split + 4 + 0.30 * (block_x - split), y0 + 0.22 * height - 4)
            self.notes = (self.scales[2] + 4, y0, block_x - 4, self.scales[3])
            return
        band = 10 * (2 * h + 1) + 2                        # the scales table: nine scales and a heading
        self.left = (x0, y0 + band + 4, split, y1)
        self.scales = (x0, y0, x0 + 50.0, y0 + band)
        self.notes = (x0 + 54.0, y0, split, y0 + band)
        low = block_top + 0.5 * (y1 - block_top)
        self.witt = (split + 4, low, x1, y1)
        middle = split + 4 + 0.42 * (x1 - split - 4)
        self.resistance = (split + 4, block_top, middle - 4, low - 4)
        self.flywheel = (middle, block_top, x1, low - 4)


class _Scales(dict):
    """The sheet's scales by symbol."""


def _choose_scales(drawing: Drawing, data: _SheetData, layout: _Layout) -> _Scales:
    """Standard scales: ψ over the left column's width; each ψ diagram's span in its panel's
    height; ΔT and I'' so that both their ψ diagram and the energy–inertia diagram fit."""
    x0, y0, x1, y1 = layout.left
    heights = _panel_heights(layout)
    plot_w = (x1 - x0) - 45
    s = _Scales()
    s["psi"] = drawing.use(Scale("μ_ψ", standard_scale(2 * np.pi, 0.7 * plot_w, plot_w), "rad/mm"))
    s["M"] = drawing.use(Scale("μ_M", fitting_scale(_span(data.moment, data.driving, 0.0), heights[0]), "(N·m)/mm"))
    s["A"] = drawing.use(Scale("μ_A", fitting_scale(_span(data.work_resistance, data.work_driving, 0.0), heights[1]),
                               "J/mm"))
    t = data.tangents
    wx0, wy0, wx1, wy1 = layout.witt
    witt_h = (wy1 - wy0) - 30 - WITT_WORDS * 1.6 * 0.8 * layout.text
    energy_diag = fitting_scale(_span(data.energy, 0.0), heights[2])
    energy_witt = fitting_scale(_span(data.energy, 0.0, t.intercept_upper, t.intercept_lower), witt_h)
    s["T"] = drawing.use(Scale("μ_T", max(energy_diag, energy_witt), "J/mm"))
    s["I"] = drawing.use(Scale("μ_I", fitting_scale(_span(data.inertia_variable, 0.0), min(heights[3], (wx1 - wx0) - 90)),
                               "(kg·m²)/mm"))
    swing = float(np.ptp(data.omega)) or 0.01 * data.mean_speed
    mu_omega = fitting_scale(swing, 0.8 * heights[4])
    top = max(float(np.max(data.omega)), data.mean_speed)
    while (top - _omega_axis(data, mu_omega)) / mu_omega > heights[4] + 1e-9:   # the axis' round value too
        mu_omega = nice_scale(mu_omega * (1 + 1e-6))
    s["omega"] = drawing.use(Scale("μ_ω", mu_omega, "(rad/s)/mm"))
    return s


def _omega_axis(data: _SheetData, mu_omega: float) -> float:
    """The round value of ω (rad/s) the ω(ψ) diagram's ψ axis is drawn at, a little below ω_min."""
    swing = float(np.ptp(data.omega)) or 0.01 * data.mean_speed
    return _nice_floor(float(np.min(data.omega)) - 0.1 * swing, mu_omega * 10)


def _span(*values) -> float:
    arr = np.concatenate([np.atleast_1d(np.asarray(v, float)) for v in values])
    return float(np.ptp(arr)) or 1.0


# ----------------------------------------------------------------------------------------------
# the ψ diagrams
# ----------------------------------------------------------------------------------------------

#: the five ψ panels, top to bottom, and their share of the left column's height
PANELS = (("M", 0.85), ("A", 0.85), ("T", 1.4), ("I", 1.15), ("omega", 0.75))


def _panel_heights(layout: _Layout) -> list[float]:
    x0, y0, x1, y1 = layout.left
    total = sum(w for _, w in PANELS)
    return [(y1 - y0) * w / total - layout.pad for _, w in PANELS]


def _psi_panels(drawing: Drawing, data: _SheetData, scales: _Scales, layout: _Layout) -> None:
    x0, y0, x1, y1 = layout.left
    total = sum(w for _, w in PANELS)
    top = y1
    h, hd = layout.text, layout.heading
    for key, weight in PANELS:
        height = (y1 - y0) * weight / total
        box = (x0, top - height, x1, top)
        top -= height
        if key == "M":
            series = [(data.moment, "M_red", False)]
            lines = [(data.driving, "M_d")]
            _psi_diagram(drawing, box, scales, "M", series, 0.0, "M_red, N·m",
                         "Reduced moment of the loads M_red(ψ) and the driving moment M_d", h, hd, lines=lines)
        elif key == "A":
            series = [(data.work_resistance, "A_c", False), (data.work_driving, "A_d", True)]
            _psi_diagram(drawing, box, scales, "A", series, 0.0, "A, J",
                         "Works of the resistance A_c(ψ) and of the driving moment A_d(ψ)", h, hd)
        elif key == "T":
            _psi_diagram(drawing, box, scales, "T", [(data.energy, "ΔT", False)], 0.0, "ΔT, J",
                         "Change of kinetic energy ΔT(ψ) = A_d + A_c", h, hd)
        elif key == "I":
            _psi_diagram(drawing, box, scales, "I", [(data.inertia_constant + data.inertia_variable, "I_red", False)],
                         data.inertia_constant, "I_red, kg·m²",
                         f"Reduced moment of inertia I_red(ψ) = I_0 + I''(ψ); axis at I_0 = "
                         f"{_num(data.inertia_constant)} kg·m²", h, hd)
        else:
            wm = data.mean_speed
            base = _omega_axis(data, scales["omega"].value)
            lines = [(wm, "ω_m")]
            _psi_diagram(drawing, box, scales, "omega", [(data.omega, "ω", False)], base, "ω, rad/s",
                         f"Angular velocity of the crank ω(ψ); axis at ω = {_num(base)} rad/s", h, hd, lines=lines)


def _psi_diagram(drawing: Drawing, box, scales: _Scales, key: str, series, base: float, axis_label: str,
                 caption: str, h: float, hd: float, lines=()) -> None:
    """One diagram over ψ in ``box``: the ψ axis at the value ``base``, the ordinates at the table
    positions, each series' polygon through its points (``(values, label, dashed)``), the
    horizontal ``lines`` ``(value, label)`` dashed, value ticks and the position numbers."""
    x0, y0, x1, y1 = box
    drawing.region(f"diagram {key}", box)
    mu_psi, mu = scales["psi"], scales[key]
    values = np.concatenate([np.asarray(v, float) for v, _, _ in series] + [np.array([base] + [v for v, _ in lines])])
    lo, hi = float(values.min()), float(values.max())
    ox = x0 + 30.0
    bottom = y0 + 2.2 * h + 2.0                           # room for the position numbers
    oy = bottom + (base - lo) / mu.value
    view = drawing.view(mu_psi, origin=(ox, oy), at=(0.0, base), scale_y=mu)
    psi = np.arange(len(series[0][0])) * 2 * np.pi / (len(series[0][0]) - 1)
    end = ox + 2 * np.pi / mu_psi.value
    drawing.add(Arrow((ox, oy), (end + 10, oy), layer="diagrams", width=0.35, head=3.0))
    psi_label = drawing.add(Text((end + 12, oy), "ψ", height=h, anchor=("left", "middle")))
    ytop = oy + (hi - base) / mu.value
    ybot = oy + (lo - base) / mu.value
    drawing.add(Arrow((ox, min(ybot, oy)), (ox, ytop + 8), layer="diagrams", width=0.35, head=3.0))
    drawing.add(Text((ox + 2, ytop + 8), axis_label, height=h, anchor=("left", "top")))
    drawing.add(Text((x0 + 2, y1 - 1), caption, height=hd, anchor=("left", "top")))
    placed = _position_numbers(drawing, ox, min(oy, ybot) - 1.5, psi / mu_psi.value, _small(h, 0.7)) + [psi_label.box()]
    main = series[0][0]
    for p, v in zip(psi, main):
        if abs(v - base) / mu.value > 0.3:
            view.line([(p, base), (p, v)], layer="dimensions", width=0.18)
    for values_k, label, dashed in series:
        pts = np.column_stack([psi, values_k])
        view.line(pts, layer="diagrams", width=0.5, dashed=dashed)
        for p in pts:
            view.circle(p, 0.6, layer="diagrams", width=0.25, filled=True)
        k = int(np.argmax(np.abs(np.asarray(values_k)[:-1] - base)))   # beside the extreme (not the end) point
        _free_label(drawing, view.paper((psi[k], values_k[k])), label, h, placed, gap=2.0)
    for value, label in lines:
        view.line([(0.0, value), (2 * np.pi, value)], layer="diagrams", width=0.35, dashed=True)
        _free_label(drawing, view.paper((2 * np.pi, value)), f"{label} = {_num(value)}", _small(h, 0.8), placed, gap=1.5)
    _value_ticks(drawing, ox, oy, base, lo, hi, mu.value, _small(h, 0.8))


def _position_numbers(drawing: Drawing, ox: float, y: float, x_mm, h: float) -> list:
    """The table positions' numbers 1 .. n+1 under a ψ axis at ``ox + x_mm`` (every k-th of more
    than 24); returns their boxes."""
    n = len(x_mm) - 1
    every = max(1, math.ceil(n / 24))
    boxes = []
    for i in range(0, n + 1, every):
        boxes.append(drawing.add(Text((ox + x_mm[i], y), str(i + 1), height=h, anchor=("center", "top"))).box())
    return boxes


def _value_ticks(drawing: Drawing, ox: float, oy: float, base: float, lo: float, hi: float, mu: float,
                 h: float) -> None:
    """Round values along a diagram's value axis (at least 2 text heights apart)."""
    span = max(hi, base) - min(lo, base)
    if span <= 0:
        return
    step = _nice_step(span / 4)
    while step / mu < 2.2 * h:
        step = _nice_step(step * 1.5)
    first = math.ceil(min(lo, base) / step) * step
    v = first
    while v <= max(hi, base) + 1e-9 * step:
        y = oy + (v - base) / mu
        drawing.add(Line(((ox - 1.5, y), (ox, y)), layer="diagrams", width=0.25))
        drawing.add(Text((ox - 2.0, y), _num(v, 4), height=h, anchor=("right", "middle")))
        v += step


def _caption(at, right: float, hd: float, words: str, fewer: str) -> Text:
    """A panel's heading at ``at`` (its upper left corner), in ``fewer`` words where ``words`` would
    reach past ``right`` (mm)."""
    text = Text(at, words, height=hd, anchor=("left", "top"))
    return text if text.box()[2] <= right else Text(at, fewer, height=hd, anchor=("left", "top"))


def _small(h: float, share: float) -> float:
    """A minor text's height: ``share`` of the sheet's text height ``h``, not below 2.5 mm."""
    return max(share * h, 2.5)


def _nice_step(x: float) -> float:
    """The smallest of 1, 2, 5 x 10^n at least ``x``."""
    e = math.floor(math.log10(x))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10.0**e >= x * (1 - 1e-12):
            return float(f"{m * 10.0 ** e:.12g}")
    return 10.0 ** (e + 1)


def _nice_floor(x: float, grain: float) -> float:
    """``x`` rounded down to a round value of about ``grain``."""
    step = _nice_step(grain)
    return math.floor(x / step) * step


def _num(value: float, digits: int = 4) -> str:
    """A number for people: ``digits`` significant digits, no "-0"."""
    text = f"{value:.{digits}g}"
    if "e" in text and 1e-4 <= abs(value) < 1e7:
        text = f"{value:.{max(digits - 1 - math.floor(math.log10(abs(value))), 0)}f}"
    if "e" in text:
        mant, exp = text.split("e")
        text = f"{mant}·10^{int(exp)}"
    return "0" if text in ("-0", "0") else text.replace("-", "−")


# ----------------------------------------------------------------------------------------------
# the energy–inertia diagram
# ----------------------------------------------------------------------------------------------


#: lines of words under the energy–inertia diagram
WITT_WORDS = 6


def _energy_inertia_panel(drawing: Drawing, data: _SheetData, scales: _Scales, box, h: float, hd: float) -> None:
    """ΔT against I'' with its tangents, the points k and l and the segment kl."""
    x0, y0, x1, y1 = box
    drawing.region("energy-inertia diagram", box)
    mu_t, mu_i = scales["T"], scales["I"]
    t = data.tangents
    values = np.concatenate([data.energy, [0.0, t.intercept_upper, t.intercept_lower]])
    lo, hi = float(values.min()), float(values.max())
    ox = x0 + 30.0
    words_h = WITT_WORDS * 1.6 * 0.8 * h
    oy = y0 + words_h + 12.0 + (0.0 - lo) / mu_t.value
    view = drawing.view(mu_i, origin=(ox, oy), scale_y=mu_t)
    width = float(np.max(data.inertia_variable)) / mu_i.value
    right = ox + width + 25
    drawing.add(Arrow((ox, oy), (right, oy), layer="diagrams", width=0.35, head=3.0))
    drawing.add(Text((right + 2, oy), "I'', kg·m²", height=h, anchor=("left", "middle")))
    ytop = oy + hi / mu_t.value
    drawing.add(Arrow((ox, oy + lo / mu_t.value - 4), (ox, ytop + 10), layer="diagrams", width=0.35, head=3.0))
    drawing.add(Text((ox + 2, ytop + 10), "ΔT, J", height=h, anchor=("left", "top")))
    drawing.add(Text((x0 + 2, y1 - 1), "Energy–inertia diagram (Wittenbauer): ΔT against I''", height=hd,
                     anchor=("left", "top")))
    pts = np.column_stack([data.inertia_variable, data.energy])
    view.line(pts, layer="diagrams", width=0.5)
    placed: list[tuple[float, float, float, float]] = []
    for i, p in enumerate(pts[:-1]):
        view.circle(p, 0.6, layer="diagrams", width=0.25, filled=True)
        _free_label(drawing, view.paper(p), str(i + 1), _small(h, 0.7), placed)
    # the tangents: from k (l) on the ΔT axis through the touching point and on
    for intercept, slope, touch, name in ((t.intercept_upper, t.slope_upper, t.touch_upper, "k"),
                                          (t.intercept_lower, t.slope_lower, t.touch_lower, "l")):
        reach = max(float(data.inertia_variable[touch]) * 1.15, float(np.max(data.inertia_variable)) * 1.05)
        view.line([(0.0, intercept), (reach, intercept + slope * reach)], layer="dimensions", width=0.35)
        k = view.paper((0.0, intercept))
        drawing.add(Circle(k, 0.9, layer="dimensions", width=0.25, filled=True))
        drawing.add(Text((k[0] - 2.0, k[1]), name, height=h, anchor=("right", "middle")))
    k, l_ = view.paper((0.0, t.intercept_upper)), view.paper((0.0, t.intercept_lower))
    kl = k[1] - l_[1]
    drawing.add(Line((k, l_), layer="dimensions", width=1.0))
    a_max, a_min = tangent_angles(mu_i.value, mu_t.value, data.mean_speed, data.delta)
    base = mu_i.value / (2 * mu_t.value) * data.mean_speed**2
    law = data.law
    mertsalov = law.required_constant_inertia
    graphic = mu_t.value * kl / (data.mean_speed**2 * data.delta)
    words = [
        f"tan ψ_max = (μ_I/2μ_T)·ω_m²·(1 + δ) = {base * (1 + data.delta):.4f},  ψ_max = {a_max:.2f}°",
        f"tan ψ_min = (μ_I/2μ_T)·ω_m²·(1 − δ) = {base * (1 - data.delta):.4f},  ψ_min = {a_min:.2f}°",
        f"kl = {kl:.1f} mm:  I' = μ_T·kl/(ω_m²·δ) = {_num(mu_t.value)}·{kl:.1f}/({data.mean_speed:.4g}²·"
        f"{data.delta:.4g}) = {_num(graphic)} kg·m²",
        f"(drawn against I'', so I' includes I_0 = {_num(data.inertia_constant)} kg·m²: flywheel "
        f"I_fw = I' − I_0 = {_num(graphic - data.inertia_constant)} kg·m²)",
        f"Mertsalov's table: I' = ΔT'_ab/(δ·ω_m²) = {_num(mertsalov)} kg·m² ({_percent(graphic, mertsalov)}; the "
        "tangents take T'' at ω_max and ω_min,",
        f"Mertsalov at ω_m: they differ by at most max I'' = {_num(float(np.max(data.inertia_variable)))} kg·m²)",
    ]
    text = Text((ox + width + 40, y1 - 3 * h), "\n".join(words), height=_small(h, 0.8), anchor=("left", "top"))
    if text.box()[2] > x1 - 2:                           # no room beside the diagram: under it
        text = Text((x0 + 2, y0 + 1), "\n".join(words), height=_small(h, 0.8), anchor=("left", "bottom"))
    drawing.add(text)


def _percent(value: float, reference: float) -> str:
    diff = 100 * (value / reference - 1)
    return f"{'+' if diff >= 0 else '−'}{abs(diff):.2f} %"


def _hits(box, boxes) -> bool:
    return any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in boxes)


def _free_label(drawing: Drawing, at, text: str, h: float, placed: list, gap: float = 1.2) -> None:
    """A point's label ``gap`` mm beside it, in the first of eight directions where it overlaps no
    label placed before (left out when none is free)."""
    g, d = gap, 1.5 * gap
    for dx, dy in ((g, g), (g, -g), (-g, g), (-g, -g), (0, d), (0, -d), (d, 0), (-d, 0)):
        anchor = ("left" if dx > 0 else "right" if dx < 0 else "center",
                  "bottom" if dy > 0 else "top" if dy < 0 else "middle")
        label = Text((at[0] + dx, at[1] + dy), text, height=h, anchor=anchor)
        if not _hits(label.box(), placed):
            placed.append(label.box())
            drawing.add(label)
            return


# ----------------------------------------------------------------------------------------------
# the useful resistance P(s)
# ----------------------------------------------------------------------------------------------


def useful_resistance(mech: Mechanism, phi=None) -> list[dict]:
    """The useful resistances a scheme declares as load diagrams, over the stroke.

    Parameters
    ----------
    mech : Mechanism
    phi : array_like, optional
        The table positions' input angles, rad (for a load given per position, a cycle table).

    Returns
    -------
    list of dict
        One per ``[[loads.forces]]`` entry given as a stroke diagram or a cycle table:
        ``label`` (``"F_B"``), ``quantity`` (``"B.x"``), ``stroke`` (H, in the quantity's unit),
        ``s`` and ``P`` (arrays: the travel from the working stroke's start and the load's
        magnitude there, N), ``idle`` (bool array: the point is on the idle stroke).
        A stroke diagram gives its declared points; a cycle table its table positions.
    """
    result = []
    for f in loads_of(mech).forces:
        load = f.force
        if not isinstance(load, (StrokeDiagram, CycleTable)):
            continue
        ext = extreme_positions(mech, load.quantity)
        stroke = float(ext.value_max - ext.value_min)
        if isinstance(load, StrokeDiagram):
            s = np.asarray(load.fractions, float) * stroke
            p = np.abs(np.asarray(load.values, float))
            idle = np.zeros(len(s), bool)
            if load.idle_fractions:
                s = np.concatenate([s, (1 - np.asarray(load.idle_fractions, float)) * stroke])
                p = np.concatenate([p, np.abs(np.asarray(load.idle_values, float))])
                idle = np.concatenate([idle, np.ones(len(load.idle_fractions), bool)])
        else:
            if phi is None:
                continue
            motion = analyze(mech, np.asarray(phi, float), order=1)
            value, first, _ = motion.quantity(load.quantity)
            ends = np.zeros(len(motion.phi), bool)
            ends[-1] = True                                # the last position ends the cycle
            mag = np.abs(load.magnitude(mech, motion.phi, ends))
            peak = int(np.argmax(mag))
            moving = np.sign(first * load.rotation)
            at_end = np.abs(first) <= 1e-9 * stroke
            if at_end[peak]:        # at a stroke's end: the stroke on the side where the load is larger
                n = len(mag)
                before, after = (peak - 1) if peak else n - 2, (peak + 1) if peak < n - 1 else 1
                working = moving[before] if mag[before] >= mag[after] else moving[after]
            else:
                working = moving[peak]
            working = working or 1.0
            start = ext.value_min if working > 0 else ext.value_max
            s = np.abs(value - start)
            p = mag
            # a stroke end belongs to the working stroke where it starts it (s = 0) or where the
            # table arrives there from the working stroke (not position 1, which leaves it)
            arrives = np.concatenate([[False], moving[:-1] == working])
            idle = np.where(at_end, (s > 0.5 * stroke) & ~arrives, moving == -working)
        result.append({"label": f"F_{f.point}", "quantity": load.quantity, "stroke": stroke, "s": s, "P": p,
                       "idle": idle})
    return result


def _resistance_panel(drawing: Drawing, mech: Mechanism, data: _SheetData, box, h: float, hd: float) -> None:
    x0, y0, x1, y1 = box
    drawing.region("useful resistance", box)
    drawing.add(_caption((x0 + 2, y1 - 1), x1 - 2, hd, "Useful resistance P(s) over the stroke", "Useful resistance P(s)"))
    diagrams = useful_resistance(mech, data.law.phi)
    if not diagrams:
        drawing.add(Text((x0 + 2, y1 - 3 * h), "The scheme declares no load diagram\n(a [[loads.forces]] entry "
                         "with diagram = ... or cycle = [...])", height=_small(h, 0.8), anchor=("left", "top")))
        return
    stroke = max(d["stroke"] for d in diagrams)
    peak = max(float(np.max(d["P"])) for d in diagrams) or 1.0
    unit = "rad" if diagrams[0]["quantity"].endswith(".theta") else "m"
    ox, oy = x0 + 7 * h + 4.0, y0 + 4 * h               # room left of the P axis for its values
    mu_s = drawing.use(Scale("μ_s", fitting_scale(stroke, x1 - ox - 3 * h - 12.0), f"{unit}/mm"))
    mu_p = drawing.use(Scale("μ_P", fitting_scale(peak, (y1 - y0) - 8 * h - 12), "N/mm"))
    view = drawing.view(mu_s, origin=(ox, oy), scale_y=mu_p)
    end = ox + stroke / mu_s.value
    top = oy + peak / mu_p.value
    drawing.add(Arrow((ox, oy), (end + 10, oy), layer="diagrams", width=0.35, head=3.0))
    drawing.add(Text((end + 12, oy), f"s, {unit}", height=h, anchor=("left", "middle")))
    drawing.add(Arrow((ox, oy), (ox, top + 8), layer="diagrams", width=0.35, head=3.0))
    drawing.add(Text((ox + 2, top + 8), "P, N", height=h, anchor=("left", "top")))
    _value_ticks(drawing, ox, oy, 0.0, 0.0, peak, mu_p.value, _small(h, 0.8))
    view.line([(stroke, 0.0), (stroke, peak * 0.15)], layer="dimensions", width=0.18)
    stroke_label = Text(((ox + end) / 2, oy - 1.5), f"H = {_num(stroke)} {unit}", height=_small(h, 0.8),
                        anchor=("center", "top"))
    if stroke_label.box()[0] < ox + 1.0:                # wider than the stroke: from the P axis on
        stroke_label = Text((ox + 1.0, oy - 1.5), stroke_label.text, height=stroke_label.height,
                            anchor=("left", "top"))
    drawing.add(stroke_label)
    for d in diagrams:
        s, p, idle = d["s"], d["P"], d["idle"]
        work = np.column_stack([s[~idle], p[~idle]])
        if not np.all(np.diff(work[:, 0]) >= -1e-12):   # a cycle table: its working positions by travel
            work = work[np.argsort(work[:, 0], kind="stable")]
        view.line(work, layer="diagrams", width=0.5)
        for q in work:
            view.circle(q, 0.6, layer="diagrams", width=0.25, filled=True)
        k = int(np.argmax(p))
        peak_at = view.paper((s[k], p[k]))
        label = Text((peak_at[0] - 2.0, peak_at[1] + 1.0), f"{d['label']} (along {d['quantity']})",
                     height=_small(h, 0.8), anchor=("right", "bottom"))
        if label.box()[0] < ox + 1.0:                   # would reach the P axis' values: right of the peak
            label = Text((peak_at[0] + 2.0, peak_at[1] + 1.0), label.text, height=label.height,
                         anchor=("left", "bottom"))
        drawing.add(label)
    note = Text((ox, y0 + 1), "s: travel from the start of the working stroke", height=_small(h, 0.7),
                anchor=("left", "bottom"))
    if note.box()[2] > x1 - 2:                          # fewer words in a narrow panel
        note = Text(note.at, "s from the stroke's start", height=note.height, anchor=note.anchor)
    drawing.add(note)


# ----------------------------------------------------------------------------------------------
# the flywheel and the notes
# ----------------------------------------------------------------------------------------------


def _flywheel_panel(drawing: Drawing, data: _SheetData, rim, box, h: float, hd: float) -> None:
    """The rim's half cross-section (axial section above the shaft's axis) and its numbers."""
    x0, y0, x1, y1 = box
    drawing.add(_caption((x0 + 2, y1 - 1), x1 - 2, hd, "Flywheel: a rim on the crank shaft", "Flywheel (a rim)"))
    law = data.law
    if rim is None:
        drawing.region("flywheel", box)
        drawing.add(Text((x0 + 2, y1 - 3 * h), f"No flywheel needed: I_0 = {_num(data.inertia_constant)} kg·m²\n"
                         f"exceeds I' = {_num(law.required_constant_inertia)} kg·m²;\n"
                         f"the machine runs with δ = {law.delta_actual:.4g}", height=_small(h, 0.8), anchor=("left", "top")))
        return
    rows = [["I_fw = I' − I_0", _num(rim.inertia), "kg·m²"],
            ["ρ (steel 7800, cast iron 7200)", _num(rim.density), "kg/m³"],
            ["ψ_b = b/D", _num(rim.width_ratio), "–"],
            ["ψ_h = h/D", _num(rim.height_ratio), "–"],
            ["D = (4·I_fw/(π·ρ·ψ_b·ψ_h))^(1/5)", f"{rim.diameter:.4f}", "m"],
            ["b = ψ_b·D", f"{rim.width:.4f}", "m"],
            ["h = ψ_h·D", f"{rim.height:.4f}", "m"],
            ["m = ρ·π·D·b·h", _num(rim.mass), "kg"],
            ["check: m·D²/4", _num(rim.mass * rim.diameter**2 / 4), "kg·m²"]]
    th = min(h, 3.0)
    table_box = table(drawing, (x0 + 2, y0 + 2 + (len(rows) + 1) * (2 * th + 1)), ["Rim", "Value", "Unit"], rows,
                      [0.64 * (x1 - x0 - 4), 0.21 * (x1 - x0 - 4), 0.15 * (x1 - x0 - 4)], height=th,
                      name="flywheel table")
    # the sketch between the caption and the table
    drawing.region("flywheel", (x0, table_box[3] + 1, x1, y1))
    sx0, sy0, sx1, sy1 = x0 + 2, table_box[3] + 4, x1 - 2, y1 - 2 * h - 2
    room_h, room_w = sy1 - sy0 - 4 * h, sx1 - sx0 - 50
    extent_m = rim.outer_diameter / 2 + rim.height   # above the axis: the rim and a margin
    mu_l = drawing.use(Scale("μ_l", _fit_pair(extent_m, room_h, rim.width * 2.5, room_w), "m/mm"))
    cx, cy = sx0 + 10 * _small(h, 0.7) + 0.5 * rim.width / mu_l.value, sy0 + 2 * h
    view = drawing.view(mu_l, origin=(cx, cy))
    half_b, r, half_h = rim.width / 2, rim.diameter / 2, rim.height / 2
    corners = [(-half_b, r - half_h), (half_b, r - half_h), (half_b, r + half_h), (-half_b, r + half_h)]
    section = view.line(corners, layer="outline", width=0.7, closed=True)
    _hatch(drawing, section.points, 2.5)
    axis_end = half_b + rim.width * 0.6
    view.line([(-axis_end, 0.0), (axis_end, 0.0)], layer="dimensions", width=0.25, dashed=True)
    view.text((axis_end, 0.0), "shaft axis", offset=(1.0, 0.0), height=_small(h, 0.7), anchor=("left", "middle"))
    view.line([(-half_b - rim.width * 0.1, r), (axis_end, r)], layer="dimensions", width=0.18, dashed=True)
    # dimensions: D/2 (the mean radius) on the right, h on the left, b above
    xr = half_b + rim.width * 0.3
    _dimension(view, (xr, 0.0), (xr, r), f"D/2 = {rim.diameter / 2:.3f} m", _small(h, 0.7), side="right")
    xl = -half_b - rim.width * 0.2
    _dimension(view, (xl, r - half_h), (xl, r + half_h), f"h = {rim.height:.3f} m", _small(h, 0.7), side="left")
    yb = r + half_h + rim.height * 0.35
    _dimension(view, (-half_b, yb), (half_b, yb), f"b = {rim.width:.3f} m", _small(h, 0.7), side="top")


def _fit_pair(height_m: float, room_h: float, width_m: float, room_w: float) -> float:
    """The finest standard scale drawing ``height_m`` in ``room_h`` mm and ``width_m`` in ``room_w``."""
    return max(fitting_scale(height_m, room_h), fitting_scale(width_m, room_w))


def _hatch(drawing: Drawing, corners, spacing: float) -> None:
    """45° hatching inside the axis-aligned rectangle ``corners`` (paper mm)."""
    xs, ys = [c[0] for c in corners], [c[1] for c in corners]
    ax0, ax1, ay0, ay1 = min(xs), max(xs), min(ys), max(ys)
    c = ax0 - (ay1 - ay0)
    while c < ax1:
        # the line y - ay0 = x - c, clipped to the rectangle
        xa, xb = max(ax0, c), min(ax1, c + (ay1 - ay0))
        if xb > xa:
            drawing.add(Line(((xa, ay0 + xa - c), (xb, ay0 + xb - c)), layer="outline", width=0.18))
        c += spacing


def _dimension(view, a, b, label: str, h: float, side: str) -> None:
    """A dimension line between ``a`` and ``b`` (quantity coordinates) with arrows both ways and
    its label beside it."""
    pa, pb = view.paper(a), view.paper(b)
    mid = ((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2)
    view.drawing.add(Arrow(mid, pa, layer="dimensions", width=0.25, head=2.5))
    view.drawing.add(Arrow(mid, pb, layer="dimensions", width=0.25, head=2.5))
    if side == "right":
        view.drawing.add(Text((mid[0] + 1.5, mid[1]), label, height=h, anchor=("left", "middle")))
    elif side == "left":
        view.drawing.add(Text((mid[0] - 1.5, mid[1]), label, height=h, anchor=("right", "middle")))
    else:
        view.drawing.add(Text((mid[0], mid[1] + 1.5), label, height=h, anchor=("center", "bottom")))


def _notes(drawing: Drawing, data: _SheetData, box, h: float) -> None:
    """The method and its inputs in words."""
    x0, y0, x1, y1 = box
    drawing.region("notes", box)
    law = data.law
    wm = data.mean_speed
    lines = [
        f"Course method (Mertsalov), n = {data.n} table positions, ψ from position 1",
        f"in the direction of rotation; ω_m = {wm:.4g} rad/s ({wm * 30 / math.pi:.4g} rpm), δ = {data.delta:.4g}",
        f"M_d = −A_c(2π)/(2π) = {_num(data.driving)} N·m;  A_d = M_d·ψ;  ΔT = A_d + A_c",
        f"T'' = I''·ω_m²/2;  ΔT' = ΔT − T'';  ΔT'_ab = {_num(law.details['energy_swing'])} J",
        f"I' = ΔT'_ab/(δ·ω_m²) = {_num(law.required_constant_inertia)} kg·m²;  I_0 = "
        f"{_num(data.inertia_constant)} kg·m²",
        ("I_fw = I' − I_0 = " + _num(law.flywheel_inertia) + " kg·m²") if law.flywheel_inertia is not None
        else f"no flywheel needed: the machine runs with δ = {law.delta_actual:.4g}",
        f"ω(ψ) with the flywheel: ω_max = {float(np.max(data.omega)):.4g}, ω_min = {float(np.min(data.omega)):.4g} rad/s",
    ]
    size = _small(h, 0.8)
    longest = max(len(line) for line in lines)
    size = min(size, (x1 - x0 - 4) / (0.7 * longest))
    drawing.add(Text((x0 + 2, y1 - 1), "\n".join(lines), height=size, anchor=("left", "top")))
