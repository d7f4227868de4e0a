"""Pictures of a machine's dynamics (linkage.report.machine): the data drawn equals independent
computations (the course method's formulas on the reduced characteristics, the equation of motion's
own consistency, the motor's balance speed), the figures refuse schemes without what they need,
and they save as PNG of a sensible size with every text inside the figure."""

import io

import numpy as np
import pytest

matplotlib = pytest.importorskip(
    "matplotlib", reason="pictures need the plot extra, which the test extra installs: pip install \".[test]\"")

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from PIL import Image
from scipy.integrate import cumulative_trapezoid, trapezoid

import linkage
from linkage.dynamics import dynamics_of, run_dynamics
from linkage.errors import InputError
from linkage.dynamics.reduced import reduced_characteristics
from linkage.report.machine import (
    plot_energy_inertia,
    plot_flywheel_energy,
    plot_moments_and_work,
    plot_speed_two_ways,
    plot_startup,
)

SCHEMES = ["course_slider_crank", "flying_shears"]
REPORT_PICTURES = [plot_moments_and_work, plot_energy_inertia, plot_flywheel_energy, plot_speed_two_ways]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def reports():
    return {name: run_dynamics(linkage.load(name), "course") for name in SCHEMES}


def _course_oracle(mech, delta=None):
    """Mertsalov's method recomputed from the reduced characteristics at the table angles, with
    scipy's cumulative trapezoid (docs/methods.md, steps 1-5)."""
    spec = dynamics_of(mech)
    delta = spec.delta if delta is None else delta
    n, s, wm = spec.positions, spec.rotation, abs(spec.mean_speed)
    phi = linkage.table_angles(mech, n, "extreme", s)
    ends = np.arange(n + 1) == n
    red = reduced_characteristics(mech, phi, s, extra_inertia=spec.constant_inertia, ends=ends)
    psi = np.linspace(0.0, 2 * np.pi, n + 1)
    work = cumulative_trapezoid(red.moment, psi, initial=0.0)
    md = -work[-1] / (2 * np.pi)
    energy = md * psi + work
    energy_flywheel = energy - red.inertia_variable * wm**2 / 2
    swing = np.ptp(energy_flywheel)
    required = swing / (delta * wm**2)
    constant = max(required, red.inertia_constant)
    level = constant * wm**2 / 2 + energy_flywheel - (energy_flywheel.max() + energy_flywheel.min()) / 2
    return {"psi": psi, "phi_deg": np.degrees(psi), "red": red, "work": work, "md": md, "energy": energy,
            "energy_flywheel": energy_flywheel, "swing": swing, "required": required, "constant": constant,
            "omega": s * np.sqrt(2 * level / constant), "wm": wm, "delta": delta, "s": s}


def _line(fig, gid):
    found = [line for ax in fig.axes for line in ax.lines if line.get_gid() == gid]
    assert found, f"no line {gid!r}"
    return found[0]


def _annotation(fig, gid):
    found = [t for ax in fig.axes for t in ax.texts if t.get_gid() == gid]
    assert found, f"no text {gid!r}"
    return found[0]


def _texts_inside(fig):
    """Everything the figure draws (texts, tick labels in view, legends) lies within it."""
    fig.canvas.draw()
    drawn = fig.get_tightbbox(fig.canvas.get_renderer())  # inches
    width, height = fig.get_size_inches()
    assert drawn.x0 >= -0.01 and drawn.y0 >= -0.01 and drawn.x1 <= width + 0.01 and drawn.y1 <= height + 0.01, \
        f"something is cut off: drawn {drawn} in a figure of {width} x {height} in"


def _saves_as_png_of_a_page_width(fig):
    """Nothing cut off, and a PNG at 100 dpi of 7-8 in by 4.5-9 in."""
    _texts_inside(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    width, height = Image.open(io.BytesIO(buffer.getvalue())).size
    assert 700 <= width <= 800 and 450 <= height <= 900, (width, height)
    plt.close(fig)


@pytest.mark.parametrize("name", SCHEMES)
def test_moments_and_work_are_the_trapezoid_of_the_reduced_moments(reports, name):
    mech = linkage.load(name)
    ref = _course_oracle(mech)
    fig = plot_moments_and_work(reports[name])
    x, moment = _line(fig, "positions:reduced_moment_resistance").get_data()
    np.testing.assert_allclose(x, ref["phi_deg"], atol=1e-9)
    np.testing.assert_allclose(moment, ref["red"].moment_resistance, rtol=1e-9, atol=1e-9)
    assert _line(fig, "mean-moment").get_ydata()[0] == pytest.approx(ref["md"], rel=1e-9)
    scale = np.max(np.abs(ref["work"]))
    for gid, expected in (("positions:A_c", ref["work"]), ("positions:A_d", ref["md"] * ref["psi"]),
                          ("positions:dT", ref["energy"])):
        np.testing.assert_allclose(_line(fig, gid).get_ydata(), expected, atol=1e-9 * scale, err_msg=gid)
    assert abs(ref["energy"][-1]) < 1e-9 * scale  # the cycle balances: Delta T returns to 0
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("$A_c$" in t for t in labels) and any("$M_d$" in t for t in labels)
    assert [ax.get_ylabel().split(",")[-1].strip() for ax in fig.axes if ax.get_ylabel()][:2] == ["N·m", "J"]


@pytest.mark.parametrize("name", SCHEMES)
def test_energy_inertia_diagram_is_the_closed_curve_of_the_table(reports, name):
    mech = linkage.load(name)
    ref = _course_oracle(mech)
    fig = plot_energy_inertia(reports[name])
    x, y = _line(fig, "energy-inertia").get_data()
    scale = np.max(np.abs(ref["energy"]))
    np.testing.assert_allclose(x, ref["red"].inertia_variable, rtol=1e-9)
    np.testing.assert_allclose(y, ref["energy"], atol=1e-9 * scale)
    assert x[0] == pytest.approx(x[-1], rel=1e-9) and abs(y[-1] - y[0]) < 1e-9 * scale  # closed
    numbers = [t.get_text() for t in fig.axes[0].texts if t.get_gid() == "position-number"]
    n = len(x) - 1
    assert numbers[0] == f"1 = {n + 1}"
    assert 6 <= len(numbers) <= 25 and all(int(t) <= n for t in numbers[1:])
    assert any(line.get_gid() == "extreme-position" for line in fig.axes[0].lines)
    assert fig.axes[0].get_xlabel().startswith("variable part of the reduced moment of inertia")
    assert "kg·m²" in fig.axes[0].get_xlabel() and fig.axes[0].get_ylabel().endswith(", J")


@pytest.mark.parametrize("name", SCHEMES)
def test_flywheel_energy_swing_is_the_required_inertia_times_delta_omega_squared(reports, name):
    mech = linkage.load(name)
    ref = _course_oracle(mech)
    report = reports[name]
    fig = plot_flywheel_energy(report)
    np.testing.assert_allclose(_line(fig, "positions:dT1").get_ydata(), ref["energy_flywheel"],
                               atol=1e-9 * ref["swing"])
    arrow = _annotation(fig, "swing")
    (_, top), (_, bottom) = arrow.xy, arrow.xyann
    spec = dynamics_of(mech)
    expected = report.law.required_constant_inertia * spec.delta * spec.mean_speed**2
    assert top - bottom == pytest.approx(expected, rel=1e-9)
    assert top - bottom == pytest.approx(ref["swing"], rel=1e-9)
    assert _line(fig, "energy-max").get_ydata()[0] == pytest.approx(ref["energy_flywheel"].max(), rel=1e-9)
    words = _annotation(fig, "result-text").get_text()
    flywheel = ref["required"] - ref["red"].inertia_constant
    assert flywheel > 0
    assert f"{ref['required']:.4g} kg·m²" in words and f"= {flywheel:.4g} kg·m²" in words
    assert "no flywheel" not in words


def test_flywheel_energy_says_when_no_flywheel_is_needed_with_the_report_s_own_delta():
    mech = linkage.load("course_slider_crank")
    ref = _course_oracle(mech, delta=0.5)   # I' = 593 J / (0.5 x 10.472^2) = 10.8 < I_0 = 90.26 kg m^2
    assert ref["required"] < ref["red"].inertia_constant
    fig = plot_flywheel_energy(run_dynamics(mech, "course", delta=0.5, compare=False))
    words = _annotation(fig, "result-text").get_text()
    assert "no flywheel needed" in words and "δ = 0.5," in words
    assert f"{ref['swing'] / (ref['red'].inertia_constant * ref['wm']**2):.4g}" in words


@pytest.mark.parametrize("name", SCHEMES)
def test_speed_two_ways_course_markers_and_a_periodic_steady_state(reports, name):
    mech = linkage.load(name)
    ref = _course_oracle(mech)
    report = reports[name]
    fig = plot_speed_two_ways(report)
    np.testing.assert_allclose(_line(fig, "positions:omega").get_ydata(), ref["omega"], rtol=1e-9)
    phi_deg, omega = (np.asarray(v, float) for v in _line(fig, "curve:omega-ode").get_data())
    eps = np.asarray(_line(fig, "curve:eps-ode").get_ydata(), float)
    assert phi_deg[0] == 0 and phi_deg[-1] == pytest.approx(360.0)
    assert np.all(np.sign(omega) == ref["s"])
    assert omega[-1] == pytest.approx(omega[0], rel=1e-6) and eps[-1] == pytest.approx(eps[0], rel=1e-5)  # periodic
    w = np.abs(omega)
    mean = (w.max() + w.min()) / 2
    assert mean == pytest.approx(ref["wm"], rel=1e-3)
    delta_ode = (w.max() - w.min()) / mean
    # the same machine (course inertia, constant moment) by the exact energy method on its own grid
    assert delta_ode == pytest.approx(report.comparison["course_delta_exact"], rel=5e-3)
    if name == "flying_shears":  # 72 positions resolve the cut: close to the course method's own delta
        assert delta_ode == pytest.approx(ref["delta"], rel=0.02)
    # eps is the derivative of omega along the motion: eps = |omega| d omega / d psi
    psi = np.radians(phi_deg)
    fd = w * np.gradient(omega, psi)
    assert np.median(np.abs(fd - eps)) < 0.01 * np.ptp(eps)
    band = sorted(line.get_ydata()[0] for line in fig.axes[0].lines if line.get_gid() == "delta-band")
    expected = sorted(ref["s"] * ref["wm"] * (1 + k * ref["delta"] / 2) for k in (-1, 1))
    np.testing.assert_allclose(band, expected, rtol=1e-9)
    assert _line(fig, "mean-speed").get_ydata()[0] == pytest.approx(ref["s"] * ref["wm"], rel=1e-9)
    ylabels = [ax.get_ylabel().replace("\n", " ") for ax in fig.axes if ax.get_ylabel()]
    assert ylabels[0].endswith("rad/s") and ylabels[1].endswith("rad/s²")


def test_startup_curves_start_at_their_speeds_and_approach_the_motor_s_steady_speed():
    mech = linkage.load("flying_shears")
    spec = dynamics_of(mech)
    fig = plot_startup(mech, cycles=3)
    curves = sorted((line for line in fig.axes[0].lines if str(line.get_gid()).startswith("startup:")),
                    key=lambda line: line.get_gid())
    wm = abs(spec.mean_speed)
    assert [line.get_ydata()[0] for line in curves] == pytest.approx([0.0, 0.5 * wm, wm, 1.5 * wm], abs=1e-9)
    steady = _line(fig, "steady-mean-speed").get_ydata()[0]
    # over a settled turn the motor delivers the cycle's mean moment (the exact energy method's, on a
    # fine grid); its moment is nearly linear in the slip, so the turn's average speed is the
    # motor's balance speed for that moment
    needed = run_dynamics(mech, "exact", compare=False).law.driving_moment
    balance = spec.motor.balance_speed(needed)
    for line in curves:
        turns, w = (np.asarray(v, float) for v in line.get_data())
        assert turns[-1] == pytest.approx(3.0) and np.all(w >= 0)
        last = turns >= 2.0
        average = trapezoid(w[last], turns[last]) / np.ptp(turns[last])
        assert average == pytest.approx(balance, rel=2e-3)
        assert (w[last].max() + w[last].min()) / 2 == pytest.approx(steady, rel=5e-3)
    assert abs(steady / balance - 1) < 0.02  # (max + min) / 2 sits below the average: the cut's dip
    assert _line(fig, "declared-mean-speed").get_ydata()[0] == pytest.approx(wm)
    assert fig.axes[0].get_ylabel().endswith("rad/s") and "turns" in fig.axes[0].get_xlabel()
    _saves_as_png_of_a_page_width(fig)


def test_pictures_refuse_a_scheme_without_dynamics_a_motor_or_the_course_table():
    four_bar = linkage.load("four_bar")
    report = run_dynamics(four_bar, "course", delta=0.05, mean_speed=10.0, compare=False)
    for picture in REPORT_PICTURES:
        with pytest.raises(InputError, match=r"scheme 'four_bar' declares no \[dynamics\] section: no "):
            picture(report)
    with pytest.raises(InputError, match=r"'four_bar' declares no \[dynamics\] section: no start-up"):
        plot_startup(four_bar)
    with pytest.raises(InputError, match=r"'course_slider_crank' declares no motor"):
        plot_startup(linkage.load("course_slider_crank"))
    exact = run_dynamics(linkage.load("course_slider_crank"), "exact", compare=False)
    with pytest.raises(InputError, match="'exact' method"):
        plot_energy_inertia(exact)
    with pytest.raises(InputError, match="at least one initial speed"):
        plot_startup(linkage.load("flying_shears"), [], cycles=1)


@pytest.mark.parametrize("name", SCHEMES)
def test_report_pictures_save_as_png_of_a_page_width_with_nothing_cut_off(reports, name):
    for picture in REPORT_PICTURES:
        _saves_as_png_of_a_page_width(picture(reports[name]))
