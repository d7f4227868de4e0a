"""One convention for people: analogs with respect to the angle turned (docs/conventions.md).

psi is the crank angle turned from position 1 in the direction of rotation: the ``phi_deg``
column of the tables and the x axis of the diagrams. Whatever people see gives the analogs
d/dpsi, so that a curve and its analog agree by graphical differentiation for either sense of
rotation; the Python API (``Motion``) keeps d/dphi of the absolute angle.

The oracles are independent of the library: central differences of a table's (or a diagram's)
own position curve over its own axis, and the closed form of the offset slider-crank.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import linkage
from _cli_io import read_csv, run

# course_slider_crank.toml (and slider_crank.toml): crank OA, rod AB, guide along x at y = e
L1, L2, E_OFF = 0.0742, 0.2225, 0.01335
N = 360   # table positions: steps of 1 deg


def closed_form_x(phi):
    """x of the slider B: A = l1 (cos, sin), |AB| = l2, B on y = e right of A."""
    return L1 * np.cos(phi) + np.sqrt(L2**2 - (E_OFF - L1 * np.sin(phi)) ** 2)


def closed_form_dx_dphi(phi):
    """dx_B/dphi of the absolute crank angle, differentiated by hand."""
    u = E_OFF - L1 * np.sin(phi)
    return -L1 * np.sin(phi) + L1 * np.cos(phi) * u / np.sqrt(L2**2 - u**2)


def counter_clockwise_course(tmp_path):
    """course_slider_crank with a positive mean speed: the same press turning counter-clockwise."""
    text = linkage.shipped_schemes()["course_slider_crank"].read_text(encoding="utf-8")
    assert "mean_speed = -10.472" in text
    path = tmp_path / "course_ccw.toml"
    path.write_text(text.replace("mean_speed = -10.472", "mean_speed = 10.472"), encoding="utf-8")
    return str(path)


def analyze_csv(capsys, scheme, *options):
    code, out, err = run(capsys, "analyze", scheme, "--format", "csv", *options)
    assert code == 0, err
    return read_csv(out)


def central(values, x):
    """First and second central differences at the interior points, and error bounds of each
    (h^2/6 max|f'''| and h^2/12 max|f''''|, from the values' own third and fourth differences)."""
    h = np.diff(x)
    assert np.allclose(h, h[0], rtol=1e-9, atol=1e-12)
    h = h[0]
    d1 = (values[2:] - values[:-2]) / (2 * h)
    d2 = (values[2:] - 2 * values[1:-1] + values[:-2]) / h**2
    third = np.abs(np.diff(values, 3)).max() / h**3
    fourth = np.abs(np.diff(values, 4)).max() / h**4
    return d1, d2, h**2 / 6 * third, h**2 / 12 * fourth


def sense_cases(tmp_path):
    return [("course_slider_crank", -1), ("slider_crank", 1), (counter_clockwise_course(tmp_path), 1)]


# ----------------------------------------------------------------------------------------------
# the table of `linkage analyze`
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", [0, 1, 2], ids=["clockwise course", "slider_crank", "course turned ccw"])
def test_analyze_analogs_are_the_slopes_of_their_own_columns(capsys, tmp_path, case):
    """Every analog column of `linkage analyze --format csv` is the central difference of its own
    position column over phi_deg (rad), to the difference's accuracy, for either sense."""
    scheme, sense = sense_cases(tmp_path)[case]
    code, out, err = run(capsys, "analyze", scheme, "--format", "json", "--positions", "4")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["direction"] == sense and doc["analogs"].startswith("d/dpsi")
    cols = analyze_csv(capsys, scheme, "--positions", str(N))
    psi = np.radians(cols["phi_deg"])
    np.testing.assert_allclose(np.diff(cols["phi_deg"]), 360.0 / N, rtol=1e-12)
    names = [n for n in cols if n.endswith((".x", ".y", ".theta", ".s"))]
    assert "B.x" in names and "2.theta" in names and "slide.s" in names
    for name in names:
        values = np.unwrap(cols[name]) if name.endswith(".theta") else cols[name]
        d1, d2, err1, err2 = central(values, psi)
        np.testing.assert_allclose(cols[name + "'"][1:-1], d1, rtol=0, atol=1.5 * err1 + 1e-12, err_msg=name)
        np.testing.assert_allclose(cols[name + "''"][1:-1], d2, rtol=0, atol=1.5 * err2 + 1e-9, err_msg=name)


def test_clockwise_slider_falls_where_its_analog_is_negative(capsys):
    """The issue's example: course_slider_crank turns clockwise; x_B falls from position 1 to
    position 4 (0.296 -> 0.208 m) and x'_B is negative there."""
    cols = analyze_csv(capsys, "course_slider_crank")
    assert cols["B.x"][0] == pytest.approx(0.2964, abs=1e-4) and cols["B.x"][3] == pytest.approx(0.2079, abs=1e-4)
    assert np.all(np.diff(cols["B.x"][:4]) < 0)
    assert np.all(cols["B.x'"][1:4] < 0)
    # and against the closed form: dx/dpsi = -dx/dphi at the absolute angles of the table
    phi = cols["1.theta"]
    np.testing.assert_allclose(cols["B.x"], closed_form_x(phi), atol=1e-12)
    np.testing.assert_allclose(cols["B.x'"], -closed_form_dx_dphi(phi), atol=1e-10)


def test_a_counter_clockwise_turn_gives_the_same_analogs_as_the_api(capsys):
    cols = analyze_csv(capsys, "slider_crank")
    np.testing.assert_allclose(cols["B.x'"], closed_form_dx_dphi(cols["1.theta"]), atol=1e-10)


# ----------------------------------------------------------------------------------------------
# the Python API keeps d/dphi
# ----------------------------------------------------------------------------------------------


def test_motion_columns_keep_d_dphi_of_the_absolute_angle():
    mech = linkage.load("course_slider_crank")
    phi = linkage.table_angles(mech, 12, direction=-1)
    motion = linkage.analyze(mech, phi, order=2)
    assert motion.direction == -1
    cols = motion.columns()
    np.testing.assert_allclose(cols["B.x"], closed_form_x(phi), atol=1e-12)
    np.testing.assert_allclose(cols["B.x'"], closed_form_dx_dphi(phi), atol=1e-10)
    np.testing.assert_allclose(motion.quantity("B.x")[1], closed_form_dx_dphi(phi), atol=1e-10)
    np.testing.assert_allclose(motion.point_analogs("B")[0][:, 0], closed_form_dx_dphi(phi), atol=1e-10)
    h = 1e-4   # second analog: five-point difference of the closed form over phi
    f = [closed_form_x(phi + k * h) for k in (-2, -1, 0, 1, 2)]
    d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
    np.testing.assert_allclose(cols["B.x''"], d2, atol=1e-6)


# ----------------------------------------------------------------------------------------------
# the diagrams
# ----------------------------------------------------------------------------------------------


def _line(fig, gid):
    found = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == gid]
    assert len(found) == 1, gid
    return np.asarray(found[0].get_xdata(), float), np.asarray(found[0].get_ydata(), float)


@pytest.mark.parametrize("direction", [-1, 1], ids=["clockwise", "counter-clockwise"])
def test_plot_motion_draws_each_analog_as_the_slope_of_its_curve(direction):
    """The curves plot_motion draws, read back from matplotlib: the analog's y data is the
    central difference of the position curve's y data over its x data (deg -> rad)."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from linkage.report.plots import plot_motion

    mech = linkage.load("course_slider_crank")
    motion = linkage.analyze(mech, linkage.table_angles(mech, 12, direction=direction), order=2)
    fig = plot_motion(motion, ["B.x", "B.x'", "B.x''"], points=N)
    try:
        x, y = _line(fig, "curve:B.x")
        x1, y1 = _line(fig, "curve:B.x'")
        x2, y2 = _line(fig, "curve:B.x''")
        np.testing.assert_array_equal(x1, x)
        np.testing.assert_array_equal(x2, x)
        assert x[0] == 0.0 and x[-1] == 360.0
        d1, d2, err1, err2 = central(y, np.radians(x))
        np.testing.assert_allclose(y1[1:-1], d1, rtol=0, atol=1.5 * err1 + 1e-12)
        np.testing.assert_allclose(y2[1:-1], d2, rtol=0, atol=1.5 * err2 + 1e-9)
        # the table's positions on the analog's curve: direction * dx/dphi of the closed form
        px, py = _line(fig, "positions:B.x'")
        np.testing.assert_allclose(py, direction * closed_form_dx_dphi(motion.phi), atol=1e-10)
        assert "d\\psi" in fig.axes[1].get_ylabel()
    finally:
        matplotlib.pyplot.close(fig)


def test_plot_columns_of_the_api_take_the_direction():
    """plot_columns of Motion.columns() (d/dphi) with direction=motion.direction draws d/dpsi; a
    table for people (kinematics_results) is drawn as it is: the same curve."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from linkage.report.plots import plot_columns
    from linkage.report.results import kinematics_results

    mech = linkage.load("course_slider_crank")
    table = kinematics_results(mech)
    motion = table.motion
    ax_api = plot_columns(motion.columns(), ["B.x'"], mechanism=mech, direction=motion.direction)
    ax_people = plot_columns(table.columns, ["B.x'"], mechanism=mech)
    try:
        (api,) = ax_api.get_lines()[:1]
        (people,) = ax_people.get_lines()[:1]
        np.testing.assert_array_equal(api.get_ydata(), people.get_ydata())
        np.testing.assert_allclose(people.get_ydata(), -closed_form_dx_dphi(motion.phi), atol=1e-10)
    finally:
        matplotlib.pyplot.close(ax_api.figure)
        matplotlib.pyplot.close(ax_people.figure)


def test_the_words_say_per_rad_turned():
    from linkage.report.words import describe_column

    mech = linkage.load("course_slider_crank")
    assert describe_column("phi_deg", mech).axis == "crank angle turned from position 1 $\\psi$, deg"
    words = describe_column("B.x'", mech)
    assert words.derivative == "$dx_{\\mathrm{B}}/d\\psi$" and words.note == "per rad of crank rotation"
