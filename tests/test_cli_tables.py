"""Tables for people and their conventions on the command line (issue 8).

- one angle convention: ``i`` from 1, ``phi_deg`` the input angle travelled from position 1 in the
  direction of rotation (0 .. 360 in either sense), the absolute input angle in the input link's
  ``L.theta``, every link angle in (-pi, pi] rad and every force direction in (-180, 180] deg;
- units under the names, frame points left out of the table for people (kept in CSV / JSON),
  ``--columns`` with names and shell-style patterns, default tables at most 160 characters wide;
- defaults that follow the scheme (positions, start), CSV of ``dynamics``, ``--transient``;
- refusals and notes in the command line's terms.

Every number compared is computed here from the geometry (closed forms, finite differences of
closed-form positions, the virtual-work balance), never copied from the library's output.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import linkage

from _cli_io import read_csv, read_table, run
from _texts import four_bar_toml

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = list(linkage.shipped_schemes())
WITH_DYNAMICS = [s for s in SHIPPED if linkage.load(s).extra.get("dynamics") is not None]

# slider_crank.toml: crank OA, rod AB, guide along x at y = e; the far dead centre
L1, L2, E_OFF = 0.0742, 0.2225, 0.01335
PHI0 = math.asin(E_OFF / (L1 + L2))
# four_bar.toml: O = (0, 0), C = (0.3, 0), OA, AB, CB
FB_OA, FB_AB, FB_CB, FB_C = 0.1, 0.3, 0.25, np.array([0.3, 0.0])


def csv_of(capsys, *argv):
    code, out, err = run(capsys, *argv, "--format", "csv")
    assert code == 0, err
    return read_csv(out), err


def json_of(capsys, *argv):
    code, out, err = run(capsys, *argv, "--format", "json")
    assert code == 0, err
    return json.loads(out), err


def table_lines(out):
    """The lines of a table for people without its ``#`` lines."""
    return [ln for ln in out.splitlines() if not ln.startswith("#")]


def wrapped(angle):
    """``angle`` (rad) in (-pi, pi]."""
    return math.pi - np.mod(math.pi - np.asarray(angle, float), 2 * math.pi)


def slider_crank_B_x(phi):
    return L1 * np.cos(phi) + np.sqrt(L2**2 - (E_OFF - L1 * np.sin(phi)) ** 2)


def four_bar_B(phi):
    """B of the four-bar: on the circles (A, AB) and (C, CB), left of the line A -> C."""
    A = FB_OA * np.array([math.cos(phi), math.sin(phi)])
    d = np.linalg.norm(FB_C - A)
    u = (FB_C - A) / d
    along = (FB_AB**2 - FB_CB**2 + d**2) / (2 * d)
    return A + along * u + math.sqrt(FB_AB**2 - along**2) * np.array([-u[1], u[0]])


def five_point(f, x, h):
    """First and second derivatives of f at x by five-point central differences."""
    v = [f(x + k * h) for k in (-2, -1, 0, 1, 2)]
    return (v[0] - 8 * v[1] + 8 * v[3] - v[4]) / (12 * h), \
        (-v[0] + 16 * v[1] - 30 * v[2] + 16 * v[3] - v[4]) / (12 * h * h)


def scheme_file(tmp_path, name, text):
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


# ----------------------------------------------------------------------------------------------
# one angle convention
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("scheme, sense", [("slider_crank", 1), ("course_slider_crank", -1)])
def test_phi_deg_runs_0_to_360_in_either_sense_and_the_input_angle_is_absolute(capsys, scheme, sense):
    """slider_crank turns CCW (no [dynamics]), course_slider_crank CW (mean_speed < 0): both
    tables run phi_deg = 0, 30, ... 360 from the far dead centre; 1.theta is the absolute crank
    angle phi0 + s phi_deg in (-pi, pi], and the slider follows the closed form there."""
    cols, _ = csv_of(capsys, "analyze", scheme)
    np.testing.assert_array_equal(cols["i"], np.arange(1, 14))
    np.testing.assert_array_equal(cols["phi_deg"], 30.0 * np.arange(13))
    phi = PHI0 + sense * np.radians(cols["phi_deg"])
    np.testing.assert_allclose(cols["1.theta"], wrapped(phi), rtol=0, atol=1e-12)
    np.testing.assert_allclose(cols["B.x"], slider_crank_B_x(phi), rtol=0, atol=1e-12)
    # the rod's angle is in (-pi, pi] and continuous (it swings about 0): no jump of 2 pi
    rod = np.arctan2(E_OFF - L1 * np.sin(phi), slider_crank_B_x(phi) - L1 * np.cos(phi))
    np.testing.assert_allclose(cols["2.theta"], rod, rtol=0, atol=1e-12)
    assert np.abs(np.diff(cols["2.theta"])).max() < 1.0


def test_dynamics_phi_deg_runs_0_to_360_clockwise_too(capsys):
    cols, _ = csv_of(capsys, "dynamics", "course_slider_crank")
    np.testing.assert_array_equal(cols["i"], np.arange(1, 14))
    np.testing.assert_array_equal(cols["phi_deg"], 30.0 * np.arange(13))
    assert np.all(cols["omega"] < 0)  # clockwise, signed


def test_link_angles_and_force_directions_are_in_one_half_turn(capsys):
    """Four-bar: the rocker angle atan2(B - C) in (-pi, pi]; every reaction direction is
    atan2(Ry, Rx) in (-180, 180] deg."""
    cols, _ = csv_of(capsys, "analyze", "four_bar", "--start", "0", "--positions", "24")
    phi = np.radians(cols["phi_deg"])
    rocker = np.array([math.atan2(*(four_bar_B(p) - FB_C)[::-1]) for p in phi])
    np.testing.assert_allclose(cols["3.theta"], rocker, rtol=0, atol=1e-12)
    for name in (c for c in cols if c.endswith(".theta")):
        assert np.all((cols[name] > -math.pi) & (cols[name] <= math.pi)), name
    forces, _ = csv_of(capsys, "forces", "four_bar", "--omega", "10")
    for pair in "OABC":
        angle = forces[f"{pair}.angle_deg"]
        assert np.all((angle > -180) & (angle <= 180)), pair
        gap = np.angle(np.exp(1j * np.radians(angle - np.degrees(np.arctan2(forces[f"{pair}.Ry"],
                                                                            forces[f"{pair}.Rx"])))))
        np.testing.assert_allclose(gap, 0.0, atol=1e-12, err_msg=pair)


# ----------------------------------------------------------------------------------------------
# tables for people
# ----------------------------------------------------------------------------------------------


def test_units_under_the_names_and_in_json(capsys):
    code, out, err = run(capsys, "analyze", "four_bar", "--columns", "B.*,3.theta*")
    assert code == 0, err
    names, units = table_lines(out)[:2]
    expected = {"i": "", "phi_deg": "[deg]", "B.x": "[m]", "B.y": "[m]", "B.x'": "[m/rad]",
                "B.y'": "[m/rad]", "B.x''": "[m/rad^2]", "B.y''": "[m/rad^2]", "3.theta": "[rad]",
                "3.theta'": "[rad/rad]", "3.theta''": "[rad/rad^2]"}
    assert names.split() == list(expected)
    # each unit stands right-aligned under its name
    ends = [names.index(n) + len(n) for n in expected]
    for (name, unit), end in zip(expected.items(), ends):
        assert units[end - len(unit):end] == unit, name
    code, out, err = run(capsys, "forces", "slider_crank", "--columns", "balancing_moment,B.R,slide.M")
    assert code == 0, err
    names, units = table_lines(out)[:2]
    assert units.split() == ["[deg]", "[N", "m]", "[N]", "[N", "m]"]
    doc, _ = json_of(capsys, "dynamics", "course_slider_crank")
    assert doc["units"] == {"phi_deg": "deg", "reduced_moment_resistance": "N m",
                            "reduced_moment_driving": "N m", "reduced_inertia": "kg m^2",
                            "reduced_inertia_derivative": "kg m^2/rad", "omega": "rad/s",
                            "eps": "rad/s^2", "balancing_moment": "N m"}


@pytest.mark.parametrize("command, schemes", [("analyze", SHIPPED), ("forces", SHIPPED),
                                              ("dynamics", WITH_DYNAMICS)])
def test_default_tables_of_every_shipped_scheme_fit_in_160_characters(capsys, command, schemes):
    for scheme in schemes:
        mech = linkage.load(scheme)
        code, out, err = run(capsys, command, scheme)
        assert code == 0, err
        body = table_lines(out)
        assert max(len(ln) for ln in body) <= 160, (scheme, max(len(ln) for ln in body))
        table = read_table(out)
        assert list(table)[:2] == ["i", linkage.kinematics.motion.position_column(mech)]
        every, _ = csv_of(capsys, command, scheme)
        assert set(table) <= set(every)
        if command == "analyze":  # frame points are constant: left out for people, kept in CSV
            frame_points = {f"{p}.x" for p in mech.links[mech.frame].points}
            assert frame_points <= set(every) and not frame_points & set(table), scheme
        shown_all = len(table) == len(every)
        said = [ln for ln in out.splitlines() if ln.startswith("# columns:")]
        assert (said == []) if shown_all else ("--columns '*'" in said[0] and "csv" in said[0]), scheme
        if command == "dynamics":
            assert shown_all  # the whole per-position table fits


def test_columns_names_and_patterns_in_their_order_in_every_format(capsys):
    cols, _ = csv_of(capsys, "analyze", "four_bar", "--columns", "B.*,3.theta")
    assert list(cols) == ["i", "phi_deg", "B.x", "B.y", "B.x'", "B.y'", "B.x''", "B.y''", "3.theta"]
    doc, _ = json_of(capsys, "analyze", "four_bar", "--columns", "B.*,3.theta")
    assert [list(r) for r in doc["rows"]] == [list(cols)] * 13
    code, out, _ = run(capsys, "analyze", "four_bar", "--columns", "B.*,3.theta")
    assert list(read_table(out)) == list(cols)
    # the order of the request, not the table's; a column is given once; the frame on request
    cols, _ = csv_of(capsys, "analyze", "four_bar", "--columns", "3.theta, B.x ,B.?,phi_deg,C.x")
    assert list(cols) == ["i", "phi_deg", "3.theta", "B.x", "B.y", "C.x"]
    np.testing.assert_allclose(cols["C.x"], 0.3, atol=1e-15)
    # the values: the four-bar's B against the closed form
    phi0 = math.radians(json_of(capsys, "analyze", "four_bar")[0]["phi0_deg"])
    for k, phi in enumerate(phi0 + np.radians(cols["phi_deg"])):
        assert (cols["B.x"][k], cols["B.y"][k]) == pytest.approx(tuple(four_bar_B(phi)), abs=1e-12)
    # '*' gives every column, in the table for people too
    every, _ = csv_of(capsys, "analyze", "four_bar")
    code, out, _ = run(capsys, "analyze", "four_bar", "--columns", "*")
    assert list(read_table(out)) == list(every)
    assert not any(ln.startswith("# columns:") for ln in out.splitlines())


def test_columns_on_forces_and_dynamics(capsys):
    cols, _ = csv_of(capsys, "forces", "four_bar", "--columns", "*.Rx,balancing_moment")
    assert list(cols) == ["i", "phi_deg", "A.Rx", "B.Rx", "C.Rx", "O.Rx", "balancing_moment"]
    cols, _ = csv_of(capsys, "dynamics", "course_slider_crank", "--columns", "omega,eps")
    assert list(cols) == ["i", "phi_deg", "omega", "eps"]


@pytest.mark.parametrize("command, scheme, request_, named", [
    ("analyze", "four_bar", "B.x,Q.x", ["unknown column 'Q.x'"]),
    ("analyze", "four_bar", "Z*", ["pattern 'Z*' matches no column"]),
    ("forces", "four_bar", "B.x,K?.R", ["unknown column 'B.x'", "pattern 'K?.R' matches no column"]),
    ("dynamics", "course_slider_crank", "M_b", ["unknown column 'M_b'"]),
    ("analyze", "four_bar", " , ", ["no column named"]),
])
def test_columns_that_name_nothing_are_refused_naming_them(capsys, command, scheme, request_, named):
    code, out, err = run(capsys, command, scheme, "--columns", request_)
    assert code == 2 and out == "" and "Traceback" not in err
    error = [ln for ln in err.splitlines() if ln.startswith("linkage: error:")]
    assert len(error) == 1 and "--columns" in error[0]
    for what in named:
        assert what in error[0]
    assert "the columns are: i, phi_deg, " in error[0]  # the available columns


def test_notes_are_said_once_per_run(capsys, tmp_path):
    """A slider without a mass: the massless-link note once per run (every run says it)."""
    text = (ROOT / "schemes" / "slider_crank.toml").read_text(encoding="utf-8")
    text = text.replace('mass = 500.0', '').replace('com = "B"', '')
    text += '\n[dynamics]\nmean_speed = -10.0\ndelta = 0.05\ninertia_0 = 1.0\n'
    path = scheme_file(tmp_path, "light", text)
    for command in ("forces", "dynamics", "dynamics"):
        code, _, err = run(capsys, command, path)
        assert code == 0, err
        assert err.count("link '3' declares no mass") == 1, err
        lines = err.splitlines()
        assert len(lines) == len(set(lines))


def test_dynamics_csv_is_the_per_position_table(capsys):
    cols, _ = csv_of(capsys, "dynamics", "course_slider_crank")
    doc, _ = json_of(capsys, "dynamics", "course_slider_crank")
    assert list(cols) == list(doc["rows"][0])
    for name in cols:
        np.testing.assert_array_equal(cols[name], [r[name] for r in doc["rows"]], err_msg=name)


def test_transient_gives_t_phi_omega_of_the_start_up(capsys):
    """flying_shears: the start-up from the declared 6 rpm over its 12 cycles. Independent check:
    t is the integral of dphi / |omega| along the rows (trapezoid)."""
    code, out, err = run(capsys, "dynamics", "flying_shears", "--method", "ode", "--transient",
                         "--format", "csv")
    assert code == 0, err
    assert "differs from the declared mean speed" not in err  # 6.55 vs 6.28 rad/s: within delta 0.08
    cols = read_csv(out)
    assert list(cols) == ["t", "phi_deg", "omega"]
    assert cols["t"][0] == 0 and cols["phi_deg"][0] == 0
    assert cols["omega"][0] == pytest.approx(6 * 2 * math.pi / 60, rel=1e-12)
    assert cols["phi_deg"][-1] == pytest.approx(12 * 360.0, rel=1e-12)
    assert np.all(np.diff(cols["t"]) > 0) and np.all(np.diff(cols["phi_deg"]) > 0)
    assert np.all(cols["omega"] > 0)  # counter-clockwise, signed
    psi = np.radians(cols["phi_deg"])
    t = np.concatenate([[0.0], np.cumsum(np.diff(psi) * (1 / cols["omega"][1:] + 1 / cols["omega"][:-1]) / 2)])
    np.testing.assert_allclose(cols["t"], t, rtol=2e-3)
    # it speeds up from 6 rpm towards the motor's steady speed, near the 60 rpm design point
    last = cols["omega"][cols["phi_deg"] >= 11 * 360.0]
    assert 2 * math.pi < (last.max() + last.min()) / 2 < 1500 / 23.5 * 2 * math.pi / 60


def test_transient_is_refused_where_it_cannot_be_meant(capsys):
    code, out, err = run(capsys, "dynamics", "flying_shears", "--transient")
    assert code == 2 and out == "" and "--transient" in err and "--method ode" in err
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--method", "ode", "--transient")
    assert code == 2 and out == "" and "--transient" in err and "initial_rpm" in err
    assert "course_slider_crank" in err and "Traceback" not in err


# ----------------------------------------------------------------------------------------------
# defaults follow the scheme
# ----------------------------------------------------------------------------------------------

# flying_shears.toml: O = (0, 0), C = (0.4, 0), OA, AB, CB; knife E 0.25 m from A, 40 deg CW from
# AB; S2, S3 mid-links; masses and J_S; knife force 2100 N at 0.3825 of its downward stroke
FS_C, FS_OA, FS_AB, FS_CB = np.array([0.4, 0.0]), 0.1, 0.4, 0.35
FS_M2, FS_J2, FS_M3, FS_J3, G = 8.0, 0.106667, 6.0, 0.06125, 9.81


def shears(phi):
    """E, S2, S3 and the angles of the coupler and the rocker at the crank angle phi."""
    A = FS_OA * np.array([math.cos(phi), math.sin(phi)])
    d = np.linalg.norm(FS_C - A)
    u = (FS_C - A) / d
    along = (FS_AB**2 - FS_CB**2 + d**2) / (2 * d)
    B = A + along * u + math.sqrt(FS_AB**2 - along**2) * np.array([-u[1], u[0]])
    e = (B - A) / FS_AB
    c, s = math.cos(math.radians(-40)), math.sin(math.radians(-40))
    E = A + 0.25 * np.array([c * e[0] - s * e[1], s * e[0] + c * e[1]])
    return {"E": E, "S2": (A + B) / 2, "S3": (FS_C + B) / 2,
            "t2": math.atan2(e[1], e[0]), "t3": math.atan2(B[1] - FS_C[1], B[0] - FS_C[0])}


def shears_balancing_moments(n):
    """M_b at the n + 1 table positions from the knife's highest position, CCW at 60 rpm, by the
    virtual-work balance M_b = -sum(F . r') with r', r'' from five-point differences of the
    closed-form positions: the knife force, gravity and the inertia of links 2 and 3."""
    h, w = 1e-3, 2 * math.pi
    knife_y1 = lambda p: five_point(lambda x: shears(x)["E"][1], p, h)[0]  # noqa: E731
    grid = np.linspace(0, 2 * math.pi, 361)
    d = np.array([knife_y1(p) for p in grid])
    roots = [brentq(knife_y1, a, b, xtol=1e-14) for a, b, da, db in zip(grid, grid[1:], d, d[1:]) if da * db < 0]
    high = max(roots, key=lambda p: shears(p)["E"][1])
    low = min(roots, key=lambda p: shears(p)["E"][1])
    y_high, y_low = shears(high)["E"][1], shears(low)["E"][1]
    moments = []
    for k in range(n + 1):
        phi = high + k * 2 * math.pi / n
        working = k < n and (phi - high) % (2 * math.pi) <= (low - high) % (2 * math.pi)
        fraction = (y_high - shears(phi)["E"][1]) / (y_high - y_low)
        force = np.interp(fraction, [0, 0.315, 0.3825, 0.45, 1], [0, 0, 2100, 0, 0]) if working else 0.0
        power = force * knife_y1(phi)  # the knife moves down: the cut pushes it up
        for point, mass, angle, inertia in (("S2", FS_M2, "t2", FS_J2), ("S3", FS_M3, "t3", FS_J3)):
            r1, r2 = five_point(lambda x, p=point: shears(x)[p], phi, h)
            at = shears(phi)[angle]  # the angle continued across the +-pi cut
            a1, a2 = five_point(lambda x, a=angle, t=at: t + wrapped(shears(x)[a] - t), phi, h)
            power += -mass * G * r1[1] - mass * w**2 * (r2 @ r1) - inertia * w**2 * a2 * a1
        moments.append(-power)
    return np.array(moments)


def test_forces_default_positions_follow_the_scheme_and_catch_the_cut(capsys):
    """flying_shears declares 72 positions: the default table has 73 rows (the same as an explicit
    --positions 72), and its balancing moment, knife force included, is the virtual-work M_b;
    the peak (the 2100 N cut) is 104.6 N m, which 12 positions miss."""
    default, _ = csv_of(capsys, "forces", "flying_shears")
    explicit, _ = csv_of(capsys, "forces", "flying_shears", "--positions", "72")
    assert list(default) == list(explicit) and len(default["i"]) == 73
    for name in default:
        np.testing.assert_array_equal(default[name], explicit[name], err_msg=name)
    expected = shears_balancing_moments(72)
    np.testing.assert_allclose(default["balancing_moment"], expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    assert np.abs(default["balancing_moment"]).max() == pytest.approx(104.63, abs=0.01)
    coarse, _ = csv_of(capsys, "forces", "flying_shears", "--positions", "12")
    assert np.abs(coarse["balancing_moment"]).max() < 10  # between the table positions


def test_analyze_positions_start_and_sense_follow_the_scheme(capsys, tmp_path):
    """A slider-crank declaring [dynamics] positions = 8, start_deg = 30, clockwise: analyze and
    forces start at 30 deg and go clockwise in 45 deg steps; the options override."""
    text = (ROOT / "schemes" / "slider_crank.toml").read_text(encoding="utf-8")
    text += '\n[dynamics]\nmean_speed = -10.0\ndelta = 0.05\npositions = 8\nstart_deg = 30\ninertia_0 = 1.0\n'
    path = scheme_file(tmp_path, "declared", text)
    for command in ("analyze", "forces"):
        cols, _ = csv_of(capsys, command, path)
        np.testing.assert_array_equal(cols["phi_deg"], 45.0 * np.arange(9))
        phi = np.radians(30.0 - cols["phi_deg"])
        if command == "analyze":
            np.testing.assert_allclose(cols["B.x"], slider_crank_B_x(phi), atol=1e-12)
            np.testing.assert_allclose(cols["1.theta"], wrapped(phi), atol=1e-12)
    cols, _ = csv_of(capsys, "analyze", path, "--positions", "4", "--start", "90")
    np.testing.assert_array_equal(cols["phi_deg"], 90.0 * np.arange(5))
    np.testing.assert_allclose(cols["B.x"], slider_crank_B_x(np.radians(90.0 - cols["phi_deg"])), atol=1e-12)


# ----------------------------------------------------------------------------------------------
# refuse what cannot be meant; notes in the command line's terms
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("argv, option, value", [
    (["forces", "four_bar", "--omega", "inf"], "--omega", "inf"),
    (["forces", "four_bar", "--omega", "nan"], "--omega", "nan"),
    (["forces", "four_bar", "--rpm", "1e200"], "--rpm", "1e200"),
    (["dynamics", "course_slider_crank", "--omega", "nan"], "--omega", "nan"),
    (["analyze", "four_bar", "--positions", "1000000000"], "--positions", "1000000000"),
    (["forces", "four_bar", "--positions", "1000000000"], "--positions", "1000000000"),
    (["dynamics", "course_slider_crank", "--positions", "1000000000"], "--positions", "1000000000"),
    (["analyze", "four_bar", "--omega", "inf"], "--omega", "inf"),  # analyze takes no speed
    (["dynamics", "course_slider_crank", "--omega", "0"], "--omega 0:", "mean_speed"),
    (["dynamics", "course_slider_crank", "--delta", "5"], "--delta 5:", "(0, 2)"),
    (["dynamics", "course_slider_crank", "--method", "exact", "--delta", "1e-12"], "--delta 1e-12:",
     "--method course"),
])
def test_bad_options_are_refused_naming_the_option_and_the_value(capsys, argv, option, value):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and "Traceback" not in err and "Warning" not in err
    assert option in err and value in err


def test_ode_without_a_motor_says_what_it_assumes(capsys):
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--method", "ode", "--format", "json")
    assert code == 0, err
    note = [ln for ln in err.splitlines() if "[dynamics.motor]" in ln]
    assert len(note) == 1 and "constant moment" in note[0]
    moment = json.loads(out)["driving_moment"]
    assert f"{moment:.6g} N m" in note[0]


def test_ode_notes_a_steady_speed_far_from_the_declared_one(capsys, tmp_path):
    """The flying shears with a 3000 rpm motor: the crank runs at about twice its declared 60 rpm,
    much more than delta = 0.08 away; the note names both speeds."""
    text = (ROOT / "schemes" / "flying_shears.toml").read_text(encoding="utf-8")
    text = (text.replace("synchronous_rpm = 1500", "synchronous_rpm = 3000")
            .replace("rated_rpm = 1400", "rated_rpm = 2900").replace("initial_rpm = 6", ""))
    path = scheme_file(tmp_path, "fast_shears", text)
    code, out, err = run(capsys, "dynamics", path, "--method", "ode", "--format", "json")
    assert code == 0, err
    mean = json.loads(out)["mean_speed_actual"]
    assert mean > 1.5 * 2 * math.pi
    note = [ln for ln in err.splitlines() if "differs from the declared mean speed" in ln]
    assert len(note) == 1 and f"{mean:.4g} rad/s" in note[0] and "6.283 rad/s" in note[0]
    assert "delta = 0.08" in note[0]


LONG_CRANK = four_bar_toml(0.3, 0.3, 0.25, 0.3, name="long_crank", tail="""[dynamics]
mean_speed = 1.0
delta = 0.1
start_deg = 0
inertia_0 = 1.0
""")


def test_cli_errors_speak_in_cli_terms(capsys, tmp_path):
    """A crank too long to turn fully: the dynamics of a cycle is refused, without the Python
    API's advice (on_failure='mask'), pointing to the command that shows the positions."""
    path = scheme_file(tmp_path, "long_crank", LONG_CRANK)
    code, out, err = run(capsys, "dynamics", path)
    assert code == 2 and out == "" and "Traceback" not in err
    assert "cannot be assembled" in err and "on_failure" not in err and "linkage analyze" in err
