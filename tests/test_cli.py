"""The ``linkage`` command line and the table formats, checked against independent oracles.

Every number compared here is computed in this file from the mechanism's geometry (closed-form
triangle / line-intersection constructions, or finite differences of positions), never copied
from the library's output.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.report import format_columns

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = list(linkage.shipped_schemes())

# slider_crank.toml: crank OA, rod AB, guide along x at y = e
L1, L2, E_OFF = 0.0742, 0.2225, 0.01335
# four_bar.toml: O = (0, 0), C = (0.3, 0), OA, AB, CB; E 0.15 m from A, 30 deg CCW from AB
FB_OA, FB_AB, FB_CB, FB_C = 0.1, 0.3, 0.25, np.array([0.3, 0.0])
# slotted_link_two_dyad.toml: O1 = (0, 0.12), O3 = (0, 0), crank 0.076, rocker 0.5, ram at y = 0.25
SL_O1, SL_R, SL_ROCKER, SL_RAM_Y = np.array([0.0, 0.12]), 0.076, 0.5, 0.25


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------


from _cli_io import read_csv, read_table, run  # noqa: E402


def analyze_csv(capsys, scheme, *options):
    code, out, err = run(capsys, "analyze", scheme, "--format", "csv", *options)
    assert code == 0, err
    return read_csv(out)


def turning_sense(scheme):
    """+1 / -1: the sense a crank scheme's tables turn in, read from its file (not from the
    library): the sign of the declared [dynamics] mean_speed or mean_rpm, +1 without one. The
    tables give the first analogs per rad turned in that sense, dq/dpsi = sense * dq/dphi
    (docs/conventions.md), second analogs unchanged."""
    import tomllib

    dynamics = tomllib.loads(linkage.shipped_schemes()[scheme].read_text(encoding="utf-8")).get("dynamics", {})
    speed = dynamics.get("mean_speed", dynamics.get("mean_rpm", 1.0))
    return -1.0 if speed < 0 else 1.0


def slider_crank_B_x(phi):
    """x of the slider: A = l1 (cos, sin), |AB| = l2, B on y = e, B right of A."""
    return L1 * np.cos(phi) + np.sqrt(L2**2 - (E_OFF - L1 * np.sin(phi)) ** 2)


def four_bar_B(phi):
    """B of the four-bar: intersection of circles (A, AB) and (C, CB) left of the line A -> C."""
    A = FB_OA * np.array([np.cos(phi), np.sin(phi)])
    d = np.linalg.norm(FB_C - A)
    u = (FB_C - A) / d
    along = (FB_AB**2 - FB_CB**2 + d**2) / (2 * d)
    across = math.sqrt(FB_AB**2 - along**2)
    candidates = [A + along * u + s * across * np.array([-u[1], u[0]]) for s in (1, -1)]
    left = [B for B in candidates if (FB_C - A)[0] * (B - A)[1] - (FB_C - A)[1] * (B - A)[0] > 0]
    return A, left[0]


def derivatives(f, x, h):
    """First and second derivatives of f at x by five-point central differences."""
    f2m, f1m, f0, f1p, f2p = (f(x + k * h) for k in (-2, -1, 0, 1, 2))
    d1 = (f2m - 8 * f1m + 8 * f1p - f2p) / (12 * h)
    d2 = (-f2m + 16 * f1m - 30 * f0 + 16 * f1p - f2p) / (12 * h * h)
    return d1, d2


# ----------------------------------------------------------------------------------------------
# linkage schemes
# ----------------------------------------------------------------------------------------------


def test_schemes_lists_every_shipped_scheme(capsys):
    code, out, err = run(capsys, "schemes")
    assert code == 0, err
    lines = out.splitlines()
    assert [ln.split()[0] for ln in lines] == SHIPPED
    by_name = {ln.split()[0]: ln for ln in lines}
    # structural formulas known from the course (docs/methods.md#structure)
    expected = {"slider_crank": "I(0,1) → II-RRP(2,3)", "four_bar": "I(0,1) → II-RRR(2,3)",
                "slotted_link": "II-RPR", "scotch_yoke": "II-RPP",
                "slotted_link_two_dyad": "I(0,1) → II-RPR(2,3) → II-PRP(4,5)"}
    for name, formula in expected.items():
        if name in by_name:
            assert formula in by_name[name]
    assert "crank OA = 0.0742 m" in by_name["slider_crank"]  # the description


# ----------------------------------------------------------------------------------------------
# every shipped scheme, every format
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("scheme", SHIPPED)
def test_analyze_formats_agree_and_have_the_contract_columns(capsys, scheme):
    mech = linkage.load(scheme)
    code, out_csv, err = run(capsys, "analyze", scheme, "--format", "csv")
    assert code == 0 and err == "", err
    code, out_json, err = run(capsys, "analyze", scheme, "--format", "json")
    assert code == 0 and err == "", err
    code, out_table, err = run(capsys, "analyze", scheme)  # table is the default
    assert code == 0 and err == "", err

    cols = read_csv(out_csv)
    names = list(cols)
    crank = mech.coordinate.is_angle
    position = "phi_deg" if crank else "s"      # a slide input's tables lead with its slide s, m
    assert names[:2] == ["i", position]
    # the contract: points (x y x' y' x'' y''), moving links (theta ...), prismatic slides (s ...)
    for p in mech.point_names:
        assert [n for n in names if n.rpartition(".")[0] == p] == \
            [f"{p}.{a}" for a in ("x", "y", "x'", "y'", "x''", "y''")]
    for link in mech.moving_links:
        assert f"{link}.theta" in names and f"{link}.theta''" in names
    prismatic = [k for k, p in mech.pairs.items() if type(p).__name__ == "Prismatic"]
    for k in prismatic:
        assert f"{k}.s" in names and f"{k}.s'" in names and f"{k}.s''" in names
    assert len(names) == 2 + 6 * len(mech.point_names) + 3 * len(mech.moving_links) + 3 * len(prismatic)

    # n equal steps (the scheme's [dynamics] positions, else 12), rows 1..n+1, row n+1 = row 1
    # + 360 deg; phi_deg counts from position 1 in the direction of rotation: 0 .. 360
    dyn = mech.extra.get("dynamics") or {}
    n = dyn.get("positions", 12)
    doc = json.loads(out_json)
    if not crank:
        _check_stroke_table(mech, cols, doc, n)
    else:
        _check_turn_table(mech, cols, doc, n, names)
    # JSON: the same numbers (exactly) with the metadata and the units
    assert doc["scheme"] == mech.name
    assert len(doc["rows"]) == n + 1
    assert doc["units"][position] == ("deg" if crank else "m") and "i" not in doc["units"]
    for k, row in enumerate(doc["rows"]):
        assert list(row) == names
        assert all(row[c] == cols[c][k] for c in names)
    # table for people: a selection of the same numbers to the printed 7 significant digits, at
    # most 160 characters wide, without the (constant) frame points, units under the names
    table = read_table(out_table)
    assert list(table)[:2] == ["i", position] and set(table) <= set(names)
    frame_points = set(mech.links[mech.frame].points)
    assert not {c.rpartition(".")[0] for c in table} & frame_points
    scale = max(np.abs(v).max() for v in cols.values())
    for c in table:
        np.testing.assert_allclose(table[c], cols[c], rtol=1e-6, atol=1e-11 * scale, err_msg=c)
    body = [ln for ln in out_table.splitlines() if not ln.startswith("#")]
    assert len({len(ln) for ln in body}) == 1  # aligned: every line equally wide
    assert len(body[0]) <= 160
    # the units line: i has none, phi_deg is in deg (s in m)
    assert body[1].split()[0] == ("[deg]" if crank else "[m]")
    assert any(ln.startswith("# columns:") and "--columns '*'" in ln for ln in out_table.splitlines())
    if not crank:   # the analogs are per m of the slide, and the table says so
        units = doc["units"]
        assert units[f"{mech.moving_links[0]}.theta'"] == "rad/m"
        assert units[f"{mech.point_names[0]}.x''"] == "m/m^2"


def _check_stroke_table(mech, cols, doc, n):
    """A slide input's table: rows 1..n+1 in n equal steps over the declared stroke, from its
    first end to its second; the input pair's slide is s."""
    start, end = mech.input_range
    np.testing.assert_array_equal(cols["i"], np.arange(1, n + 2))
    np.testing.assert_allclose(cols["s"], start + (end - start) * np.arange(n + 1) / n, rtol=0, atol=1e-12)
    pair = mech.input_pair(mech.inputs[0])
    np.testing.assert_allclose(cols[f"{pair}.s"], cols["s"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(cols[f"{pair}.s'"], 1.0, rtol=0, atol=1e-12)     # ds/ds
    np.testing.assert_allclose(cols[f"{pair}.s''"], 0.0, rtol=0, atol=1e-12)
    assert doc["s0"] == start and "phi0_deg" not in doc
    assert doc["direction"] == (1 if end > start else -1)
    for name in cols:
        if name.endswith(".theta"):
            assert np.all((cols[name] > -math.pi) & (cols[name] <= math.pi)), name


def _check_turn_table(mech, cols, doc, n, names):
    """A crank's table: n equal steps over a turn, row n+1 = row 1 + 360 deg."""
    dyn = mech.extra.get("dynamics") or {}
    phi = cols["phi_deg"]
    assert len(phi) == n + 1
    np.testing.assert_array_equal(cols["i"], np.arange(1, n + 2))
    np.testing.assert_allclose(phi, 360.0 / n * np.arange(n + 1), rtol=0, atol=1e-9)
    # the input link's angle is the absolute input angle phi0 + s phi_deg, in (-pi, pi], with the
    # sense s of the declared mean speed (else CCW)
    sense = -1.0 if dyn.get("mean_speed", dyn.get("mean_rpm", 1)) < 0 else 1.0
    assert doc["direction"] == sense
    absolute = np.radians(doc["phi0_deg"] + sense * phi)
    theta1 = cols[f"{mech.inputs[0]}.theta"]
    np.testing.assert_allclose(np.angle(np.exp(1j * (theta1 - absolute))), 0.0, rtol=0, atol=1e-12)
    for name in names:
        if name.endswith(".theta"):
            assert np.all((cols[name] > -math.pi) & (cols[name] <= math.pi)), name
    # position n+1 is position 1 again
    for name, values in cols.items():
        if name in ("i", "phi_deg"):
            continue
        if name.endswith(".theta"):
            gap = np.angle(np.exp(1j * (values[-1] - values[0])))
            assert abs(gap) < 1e-9, name
        else:
            assert values[-1] == pytest.approx(values[0], abs=1e-9), name


@pytest.mark.parametrize("scheme", SHIPPED)
def test_default_start_is_the_declared_extreme(capsys, scheme):
    """Position 1 is where the output is largest (start = "max") or smallest, over a dense sweep;
    over a declared input range (a slide input's stroke) position 1 is the range's first end,
    and --start, which picks position 1 on a turn, is refused naming the range."""
    mech = linkage.load(scheme)
    quantity = mech.output.quantity
    cols = analyze_csv(capsys, scheme)
    if mech.input_range is not None:
        first = cols["phi_deg"][0] if "phi_deg" in cols else cols["s"][0]
        assert first == (0.0 if mech.coordinate.is_angle else mech.input_range[0])
        code, _, err = run(capsys, "analyze", scheme, "--start", "0")
        a, b = mech.coordinate.shown(mech.input_range)
        declared = (f"range_deg = [{a:.10g}, {b:.10g}]" if mech.coordinate.is_angle
                    else f"range = [{a:.10g}, {b:.10g}] m")
        assert code == 2 and declared in err and "--start 0" in err, err
        return
    dense = analyze_csv(capsys, scheme, "--positions", "720", "--start", "0")
    assert abs(cols[quantity + "'"][0]) < 1e-9
    if mech.output.start == "max":
        assert cols[quantity][0] >= dense[quantity].max() - 1e-12
    else:
        assert cols[quantity][0] <= dense[quantity].min() + 1e-12


@pytest.mark.parametrize("scheme", SHIPPED)
def test_analogs_match_finite_differences_of_positions(capsys, scheme):
    """x' and x'' of every column against five-point differences of the positions (docs/methods.md#checks):
    the differences over the absolute input angle phi, times the sense of rotation for the first
    analogs (the table's are per rad turned, d/dpsi)."""
    if not linkage.load(scheme).coordinate.is_angle:
        return _slide_analogs_match_finite_differences(capsys, scheme)
    sense = turning_sense(scheme)
    phi0_deg, h_deg = 17.0, 0.5
    samples = [analyze_csv(capsys, scheme, "--positions", "1", "--start", repr(phi0_deg + k * h_deg))
               for k in (-2, -1, 0, 1, 2)]
    h = math.radians(h_deg)
    at = {n: np.array([s[n][0] for s in samples]) for n in samples[0]}
    assert at["phi_deg"][2] == 0.0  # position 1 ...
    theta1 = at[f"{linkage.load(scheme).inputs[0]}.theta"][2]
    assert theta1 == pytest.approx(math.radians(phi0_deg), abs=1e-15)  # ... is at the given angle
    size = max(np.abs(at[n]).max() for n in at if n.endswith((".x", ".y", ".s")))
    for name in at:
        if name in ("i", "phi_deg") or name.endswith("'"):
            continue
        values = np.unwrap(at[name]) if name.endswith(".theta") else at[name]
        d1 = (values[0] - 8 * values[1] + 8 * values[3] - values[4]) / (12 * h)
        d2 = (-values[0] + 16 * values[1] - 30 * values[2] + 16 * values[3] - values[4]) / (12 * h * h)
        tol = 1e-6 * (1.0 if name.endswith(".theta") else size)
        assert at[name + "'"][2] == pytest.approx(sense * d1, abs=tol), name
        assert at[name + "''"][2] == pytest.approx(d2, abs=10 * tol), name


def _slide_analogs_match_finite_differences(capsys, scheme):
    """A slide input: the analogs per m in rows of a dense table over the stroke (step h, m)
    against five-point differences of the positions of the neighbouring rows."""
    mech = linkage.load(scheme)
    n = 400
    cols = analyze_csv(capsys, scheme, "--positions", str(n))
    start, end = mech.input_range
    h = (end - start) / n   # signed: the table runs from start to end
    np.testing.assert_allclose(np.diff(cols["s"]), h, rtol=1e-9)
    size = max(np.abs(cols[c]).max() for c in cols if c.endswith((".x", ".y", ".s")))
    rows = np.arange(2, n - 1, 37)
    for name in cols:
        if name in ("i", "s") or name.endswith("'"):
            continue
        values = np.unwrap(cols[name]) if name.endswith(".theta") else cols[name]
        f = [values[rows + k] for k in (-2, -1, 0, 1, 2)]
        d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
        d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
        tol = 1e-6 * (1.0 / size if name.endswith(".theta") else 1.0)   # per m: rad/m, m/m
        np.testing.assert_allclose(cols[name + "'"][rows], d1, rtol=0, atol=tol, err_msg=name)
        np.testing.assert_allclose(cols[name + "''"][rows], d2, rtol=0, atol=10 * tol / size, err_msg=name)


# ----------------------------------------------------------------------------------------------
# the mechanisms against their geometry
# ----------------------------------------------------------------------------------------------


def test_slider_crank_against_the_closed_form(capsys):
    cols = analyze_csv(capsys, "slider_crank")
    # position 1: the far dead centre, crank and rod in line; then 30 deg steps CCW
    phi0 = math.degrees(math.asin(E_OFF / (L1 + L2)))
    np.testing.assert_array_equal(cols["phi_deg"], 30.0 * np.arange(13))
    assert cols["1.theta"][0] == pytest.approx(math.radians(phi0), abs=1e-12)
    assert cols["B.x"][0] == pytest.approx(math.sqrt((L1 + L2) ** 2 - E_OFF**2), abs=1e-12)
    # every position
    phi = np.radians(phi0 + cols["phi_deg"])
    np.testing.assert_allclose(np.angle(np.exp(1j * (cols["1.theta"] - phi))), 0.0, atol=1e-12)
    np.testing.assert_allclose(cols["A.x"], L1 * np.cos(phi), atol=1e-12)
    np.testing.assert_allclose(cols["A.y"], L1 * np.sin(phi), atol=1e-12)
    np.testing.assert_allclose(cols["B.x"], slider_crank_B_x(phi), atol=1e-12)
    np.testing.assert_allclose(cols["B.y"], E_OFF, atol=1e-12)
    np.testing.assert_allclose(cols["slide.s"], cols["B.x"], atol=1e-12)  # guide through (0, e) along x
    rod = np.arctan2(E_OFF - L1 * np.sin(phi), slider_crank_B_x(phi) - L1 * np.cos(phi))
    np.testing.assert_allclose(np.angle(np.exp(1j * (cols["2.theta"] - rod))), 0.0, atol=1e-12)
    # analogs: the derivative of the closed form, and its finite differences
    root = np.sqrt(L2**2 - (E_OFF - L1 * np.sin(phi)) ** 2)
    xb1 = -L1 * np.sin(phi) + (E_OFF - L1 * np.sin(phi)) * L1 * np.cos(phi) / root
    np.testing.assert_allclose(cols["B.x'"], xb1, atol=1e-12)
    _, xb2 = derivatives(slider_crank_B_x, phi, 1e-3)
    np.testing.assert_allclose(cols["B.x''"], xb2, atol=1e-8)
    np.testing.assert_allclose(cols["B.y'"], 0.0, atol=1e-12)


def test_four_bar_starts_at_the_rocker_extreme_and_follows_the_geometry(capsys):
    cols = analyze_csv(capsys, "four_bar")
    # the rocker's largest angle: crank and coupler folded in line, |OB| = AB - OA, with O
    # between A and B (B on the left of A -> C)
    r = FB_AB - FB_OA
    bx = (r**2 - FB_CB**2 + FB_C[0] ** 2) / (2 * FB_C[0])
    B0 = np.array([bx, math.sqrt(r**2 - bx**2)])
    phi0 = math.degrees(math.atan2(B0[1], B0[0]) + math.pi) % 360.0
    assert math.degrees(cols["1.theta"][0]) % 360.0 == pytest.approx(phi0, abs=1e-8)
    assert cols["3.theta"][0] == pytest.approx(math.atan2(B0[1], B0[0] - FB_C[0]), abs=1e-12)
    for k, phi in enumerate(np.radians(phi0 + cols["phi_deg"])):
        A, B = four_bar_B(phi)
        assert (cols["B.x"][k], cols["B.y"][k]) == pytest.approx(tuple(B), abs=1e-12)
        u = (B - A) / FB_AB
        rot30 = np.array([[math.cos(math.pi / 6), -math.sin(math.pi / 6)],
                          [math.sin(math.pi / 6), math.cos(math.pi / 6)]])
        E = A + 0.15 * rot30 @ u
        assert (cols["E.x"][k], cols["E.y"][k]) == pytest.approx(tuple(E), abs=1e-12)
        theta3 = math.atan2(B[1] - FB_C[1], B[0] - FB_C[0])
        assert math.cos(cols["3.theta"][k] - theta3) == pytest.approx(1.0, abs=1e-14)
        d1, _ = derivatives(lambda p: four_bar_B(p)[1], phi, 1e-4)
        assert (cols["B.x'"][k], cols["B.y'"][k]) == pytest.approx(tuple(d1), abs=1e-9)


def test_two_dyad_slotted_link_against_the_geometry(capsys):
    cols = analyze_csv(capsys, "slotted_link_two_dyad")
    # the ram's right extreme: the rocker is tangent to the crank circle, on the right
    d = np.linalg.norm(SL_O1)
    theta3 = math.pi / 2 - math.asin(SL_R / d)
    A0 = math.sqrt(d**2 - SL_R**2) * np.array([math.cos(theta3), math.sin(theta3)])
    phi0 = math.degrees(math.atan2(A0[1] - SL_O1[1], A0[0] - SL_O1[0])) % 360.0
    assert math.degrees(cols["1.theta"][0]) % 360.0 == pytest.approx(phi0, abs=1e-8)
    assert cols["B.x"][0] == pytest.approx(SL_RAM_Y / math.tan(theta3), abs=1e-12)
    phi = np.radians(phi0 + cols["phi_deg"])
    A = SL_O1 + SL_R * np.column_stack([np.cos(phi), np.sin(phi)])
    rocker = A / np.linalg.norm(A, axis=1)[:, None]
    np.testing.assert_allclose(cols["B.x"], SL_RAM_Y * A[:, 0] / A[:, 1], atol=1e-12)
    np.testing.assert_allclose(cols["B.y"], SL_RAM_Y, atol=1e-12)
    np.testing.assert_allclose(cols["C.x"], SL_ROCKER * rocker[:, 0], atol=1e-12)
    np.testing.assert_allclose(cols["C.y"], SL_ROCKER * rocker[:, 1], atol=1e-12)
    np.testing.assert_allclose(cols["slot_A.s"], np.linalg.norm(A, axis=1), atol=1e-12)
    np.testing.assert_allclose(cols["slot_B.s"], SL_RAM_Y / rocker[:, 1], atol=1e-12)
    np.testing.assert_allclose(cols["ram.s"], cols["B.x"], atol=1e-12)


# ----------------------------------------------------------------------------------------------
# options
# ----------------------------------------------------------------------------------------------


def test_start_angle_and_number_of_positions(capsys):
    cols = analyze_csv(capsys, "slider_crank", "--start", "30")
    assert cols["phi_deg"][0] == 0.0 and cols["1.theta"][0] == pytest.approx(math.radians(30), abs=1e-15)
    assert cols["A.x"][0] == pytest.approx(L1 * math.cos(math.radians(30)), abs=1e-15)
    assert cols["B.x"][0] == pytest.approx(slider_crank_B_x(math.radians(30)), abs=1e-12)
    cols = analyze_csv(capsys, "slider_crank", "--positions", "6", "--start", "30")
    assert list(cols["phi_deg"]) == [0.0, 60.0, 120.0, 180.0, 240.0, 300.0, 360.0]
    np.testing.assert_allclose(cols["A.x"], L1 * np.cos(np.radians(30.0 + cols["phi_deg"])), atol=1e-15)
    cols = analyze_csv(capsys, "four_bar", "--positions", "6")
    assert len(cols["phi_deg"]) == 7
    np.testing.assert_allclose(np.diff(cols["phi_deg"]), 60.0, atol=1e-9)


def test_start_min_gives_the_other_dead_centre(capsys):
    cols = analyze_csv(capsys, "slider_crank", "--start", "min", "--positions", "2")
    # near dead centre: the crank folded back on the rod
    assert cols["B.x"][0] == pytest.approx(math.sqrt((L2 - L1) ** 2 - E_OFF**2), abs=1e-12)


def test_json_metadata(capsys):
    code, out, err = run(capsys, "analyze", "slider_crank", "--format", "json", "--start", "30",
                         "--positions", "4")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["scheme"] == "slider_crank"
    assert doc["positions"] == 4 and doc["phi0_deg"] == pytest.approx(30.0, abs=1e-12)
    assert doc["failed"] == [] and doc["direction"] == 1
    assert [r["i"] for r in doc["rows"]] == [1, 2, 3, 4, 5]
    assert [r["phi_deg"] for r in doc["rows"]] == [0.0, 90.0, 180.0, 270.0, 360.0]


def test_help(capsys):
    code, out, _ = run(capsys, "analyze", "--help")
    assert code == 0 and "--positions" in out and "--start" in out and "--format" in out


# ----------------------------------------------------------------------------------------------
# errors and positions that cannot be assembled
# ----------------------------------------------------------------------------------------------


def test_unknown_scheme_exits_2_naming_it(capsys):
    code, out, err = run(capsys, "analyze", "no_such_mechanism")
    assert code == 2 and out == ""
    assert "no_such_mechanism" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_bad_scheme_file_lists_every_problem(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\ncolour = "red"\n[links.1]\nlength = 0.1\nwidth = 3\n', encoding="utf-8")
    code, out, err = run(capsys, "analyze", str(bad))
    assert code == 2 and out == "" and "Traceback" not in err
    lines = err.strip().splitlines()
    assert all(ln.startswith("linkage: error: ") for ln in lines)
    assert any("colour" in ln for ln in lines) and any("width" in ln for ln in lines)
    code, _, err = run(capsys, "analyze", str(tmp_path / "missing.toml"))
    assert code == 2 and "missing.toml" in err


@pytest.mark.parametrize("options", [["--positions", "0"], ["--positions", "x"],
                                     ["--start", "north"], ["--start", "nan"],
                                     ["--format", "xml"]])
def test_bad_options_exit_2(capsys, options):
    code, out, err = run(capsys, "analyze", "slider_crank", *options)
    assert code == 2 and out == "" and "Traceback" not in err


@pytest.mark.parametrize("error, internal", [(ValueError("boom"), True),
                                             (linkage.InputError("boom: a bad value"), False),
                                             (linkage.AssemblyError("boom: cannot be assembled"), False)])
def test_a_library_bug_is_an_internal_error_not_the_users(capsys, monkeypatch, error, internal):
    """Only the ``LinkageError`` family (and argparse's errors) are the user's input: a bare
    ``ValueError`` raised inside the library is a bug, said as such, with the internal status."""
    import linkage.report.results
    from linkage.cli import EXIT_INPUT, EXIT_INTERNAL

    def broken(*args, **kwargs):
        raise error

    monkeypatch.setattr(linkage.report.results, "analyze", broken)   # what `linkage analyze` calls
    code, out, err = run(capsys, "analyze", "four_bar")
    assert out == "" and "Traceback" not in err
    if internal:
        assert code == EXIT_INTERNAL != EXIT_INPUT
        assert err.strip() == ("linkage: error: internal error (ValueError: boom); please report it with the "
                               "command line that caused it")
    else:
        assert code == EXIT_INPUT
        assert err.strip() == f"linkage: error: {error}"


def test_an_input_law_too_fast_to_resolve_is_the_users_error(capsys):
    """A gear ratio of 1e15 leaves the further input's angle to round-off: the extreme positions
    cannot be found, and the command says so as an error of the input (it once leaked scipy's
    ValueError "f(a) and f(b) must have different signs")."""
    code, out, err = run(capsys, "analyze", "five_bar_two_input", "--input-law", "4:1e15")
    assert code == 2 and out == "" and "internal error" not in err and "Traceback" not in err
    assert "extreme positions cannot be found" in err and "different signs" not in err


def test_a_folder_that_cannot_be_made_is_the_users_error(capsys, tmp_path):
    """``--out`` under a regular file: the folder cannot be made (an OSError the user caused),
    said in one line naming the path, with the input-error status, not as an internal error."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    target = blocker / "drawings"
    code, out, err = run(capsys, "plans", "slider_crank", "--position", "3", "--omega", "-10",
                         "--format", "svg", "--out", str(target))
    assert code == 2 and "internal error" not in err and "Traceback" not in err
    assert str(blocker) in err.splitlines()[-1]


LONG_CRANK = """
name = "long_crank"
input = "1"
[links.0]
points = { O = [0.0, 0.0], C = [0.3, 0.0] }
[links.1]
line = ["O", "A"]
length = 0.3
[links.2]
line = ["A", "B"]
length = 0.3
[links.3]
line = ["C", "B"]
length = 0.25
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.C]
links = ["3", "0"]
[assembly.B]
left_of = ["A", "C"]
"""


def test_positions_that_cannot_be_assembled_are_empty_and_named(capsys, tmp_path):
    """A four-bar whose crank is too long: B exists only where |AC| is in [AB - CB, AB + CB]."""
    path = tmp_path / "long_crank.toml"
    path.write_text(LONG_CRANK, encoding="utf-8")
    n = 12
    phi_deg = np.arange(n + 1) * 360.0 / n
    A = 0.3 * np.column_stack([np.cos(np.radians(phi_deg)), np.sin(np.radians(phi_deg))])
    d = np.linalg.norm(A - FB_C, axis=1)
    broken = (d < 0.3 - 0.25) | (d > 0.3 + 0.25)
    assert broken.any() and not broken.all()

    code, out, err = run(capsys, "analyze", str(path), "--format", "csv")
    assert code == 0
    # no output declared: a note, and the table starts at 0 deg
    assert "no output" in err and "0 deg" in err
    warning = [ln for ln in err.splitlines() if "cannot be assembled" in ln]
    assert len(warning) == 1
    numbers = warning[0].split("positions i = ")[1].split(" (")[0]
    assert [int(x) for x in numbers.split(",")] == list(np.flatnonzero(broken) + 1)
    named = [float(x) for x in warning[0].split("phi = ")[1].split(" deg")[0].split(",")]
    assert named == pytest.approx(list(phi_deg[broken]))
    cols = read_csv(out)
    np.testing.assert_array_equal(cols["phi_deg"], phi_deg)
    assert np.isnan(cols["B.x"][broken]).all() and np.isfinite(cols["B.x"][~broken]).all()

    code, out, _ = run(capsys, "analyze", str(path), "--format", "json")
    doc = json.loads(out)  # strict JSON: no NaN literal
    assert [r["B.x"] is None for r in doc["rows"]] == list(broken)
    assert [f["position"] for f in doc["failed"]] == list(np.flatnonzero(broken) + 1)

    code, out, _ = run(capsys, "analyze", str(path))
    table = read_table(out)
    assert np.isnan(table["B.x"][broken]).all()


# ----------------------------------------------------------------------------------------------
# the formatter on its own
# ----------------------------------------------------------------------------------------------


def test_format_columns():
    third = 1.0 / 3.0
    cols = {"phi_deg": np.array([0.0, 90.0]), "q": np.array([third, np.nan]), "k": np.array([1, 2])}
    rows = read_csv(format_columns(cols, "csv"))
    assert rows["q"][0] == third  # full precision: exact round trip
    assert format_columns(cols, "csv").splitlines()[2] == "90.0,nan,2"
    assert json.loads(format_columns(cols, "json")) == [
        {"phi_deg": 0.0, "q": third, "k": 1}, {"phi_deg": 90.0, "q": None, "k": 2}]
    doc = json.loads(format_columns(cols, "json", meta={"scheme": "s", "n": np.int64(2)}))
    assert list(doc) == ["scheme", "n", "rows"] and doc["n"] == 2 and len(doc["rows"]) == 2
    lines = format_columns(cols, "table").splitlines()
    assert lines[0].split() == ["phi_deg", "q", "k"] and lines[1].split() == ["0", "0.3333333", "1"]
    assert len({len(ln) for ln in lines}) == 1 and all(ln[-1] != " " for ln in lines)
    with pytest.raises(ValueError, match="format"):
        format_columns(cols, "xml")
    with pytest.raises(ValueError, match="equal lengths"):
        format_columns({"phi_deg": np.zeros(2), "q": np.zeros(3)}, "csv")


# ----------------------------------------------------------------------------------------------
# the installed entry point
# ----------------------------------------------------------------------------------------------


def test_python_dash_m_linkage():
    result = subprocess.run([sys.executable, "-m", "linkage", "analyze", "slider_crank", "--format", "csv"],
                            cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    cols = read_csv(result.stdout)
    assert len(cols["phi_deg"]) == 13
    assert cols["B.x"][0] == pytest.approx(math.sqrt((L1 + L2) ** 2 - E_OFF**2), abs=1e-12)
