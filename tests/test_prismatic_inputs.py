"""Slide inputs (a piston on a frame guide, a hydraulic cylinder), checked against independent oracles.

Every number compared here comes from this file: the two shipped schemes are solved in closed form
(the law of cosines in their triangles), analogs are central finite differences, the balancing
force is the derivative of a potential (virtual work), and the law of motion of a stroke is the
constant-acceleration formula or an energy balance computed from the closed-form geometry.

piston_driven_crank: O = (0, 0), crank OA = 0.1, rod AB = 0.4 (S2 0.1 from A), B = (s, 0) on the
guide along x, A above the guide; dead centres at s = 0.3 and 0.5 m.
cylinder_boom: O = (0, 0), C = (0.6, -0.4), boom OT = 2 with B 0.8 and S1 1.0 from O; barrel at
C (S2 0.25 along C -> B), rod at B (S3 0.3 back towards C); |CB| = s; B left of O -> C.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.errors import AssemblyError, DynamicsError, DynamicsInputError, SchemeError
from linkage.kinetostatics.reactions import solve_reactions, virtual_power_residual
from linkage.dynamics.stroke import stroke_motion

from _cli_io import read_csv, read_table, run

ROOT = Path(__file__).resolve().parents[1]
G = 9.81

# piston_driven_crank
P_R, P_L, P_S2 = 0.1, 0.4, 0.1
P_MASS = {"1": 2.0, "2": 1.5, "3": 1.0}
P_MOMENT = -50.0                       # on the crank, N m
# cylinder_boom
C_C = np.array([0.6, -0.4])
C_OB, C_OT, C_OS1, C_S2, C_S3 = 0.8, 2.0, 1.0, 0.25, 0.3
C_MASS = {"1": 50.0, "2": 12.0, "3": 6.0}
C_INERTIA = {"1": 16.7, "2": 0.25, "3": 0.18}  # about each centre of mass
C_PAYLOAD = -2000.0                    # N, y force at T


# ----------------------------------------------------------------------------------------------
# scheme texts (scalable copies of the shipped schemes) and closed forms
# ----------------------------------------------------------------------------------------------


def piston_text(k=1.0, stroke=(0.48, 0.32), *, bare_mass=None):
    """piston_driven_crank with every length and the stroke times ``k``; ``bare_mass``: only the
    piston has mass (kg), no gravity and no loads."""
    a, b = (k * v for v in stroke)
    if bare_mass is None:
        masses = ['mass = 2.0\ncom = "O"\ninertia = 0.01', 'mass = 1.5\ncom = "S2"\ninertia = 0.02',
                  'mass = 1.0\ncom = "B"']
        loads = '[loads]\ngravity = [0.0, -9.81]\n[[loads.moments]]\nlink = "1"\nmoment = -50.0\n'
    else:
        masses = ["", "", f'mass = {bare_mass!r}\ncom = "B"']
        loads = ""
    return f"""
name = "piston_scaled"
input = "3"
range = [{a!r}, {b!r}]
[links.0]
points = {{ O = [0.0, 0.0] }}
guides.slide = {{ through = [0.0, 0.0], angle_deg = 0 }}
[links.1]
line = ["O", "A"]
length = {P_R * k!r}
{masses[0]}
[links.2]
line = ["A", "B"]
length = {P_L * k!r}
points.S2 = {{ from = "A", distance = {P_S2 * k!r} }}
{masses[1]}
[links.3]
points.B = [0.0, 0.0]
{masses[2]}
[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"
[assembly.A]
left_of = ["O", "B"]
{loads}"""


def cylinder_text(k=1.0, stroke=(0.6, 1.3)):
    """cylinder_boom (kinematics only) with every length and the stroke times ``k``."""
    a, b = (k * v for v in stroke)
    return f"""
name = "cylinder_scaled"
input = "K"
range = [{a!r}, {b!r}]
[links.0]
points = {{ O = [0.0, 0.0], C = [{0.6 * k!r}, {-0.4 * k!r}] }}
[links.1]
line = ["O", "T"]
length = {C_OT * k!r}
points.B = {{ from = "O", distance = {C_OB * k!r} }}
points.S1 = {{ from = "O", distance = {C_OS1 * k!r} }}
[links.2]
points = {{ C = [0.0, 0.0], S2 = [{C_S2 * k!r}, 0.0] }}
guides.axis = {{ through = [0.0, 0.0], angle_deg = 0 }}
[links.3]
points = {{ B = [0.0, 0.0], S3 = [{-C_S3 * k!r}, 0.0] }}
[pairs.O]
links = ["0", "1"]
[pairs.C]
links = ["0", "2"]
[pairs.B]
links = ["1", "3"]
[pairs.K]
kind = "P"
links = ["2", "3"]
guide = "axis"
at = "B"
[assembly.B]
left_of = ["O", "C"]
"""


def piston_closed(s, k=1.0):
    """Closed form of piston_driven_crank: the crank angle by the law of cosines in O, A, B
    (A above the guide: theta1 in [0, pi]), the rod's angle along A -> B."""
    s = np.asarray(s, dtype=float)
    r, l_ = P_R * k, P_L * k
    cos1 = (s**2 + r**2 - l_**2) / (2 * r * s)
    th1 = np.arccos(cos1)
    ax, ay = r * np.cos(th1), r * np.sin(th1)
    th2 = np.arctan2(-ay, s - ax)
    return {"1.theta": th1, "2.theta": th2, "A.x": ax, "A.y": ay, "B.x": s, "B.y": 0 * s,
            "S2.x": ax + P_S2 * k * np.cos(th2), "S2.y": ay + P_S2 * k * np.sin(th2)}


def piston_exact_analogs(s, k=1.0):
    """d theta1 / ds and d2 theta1 / ds2 differentiated by hand (for the positions next to the
    dead centre, where finite differences lose their accuracy)."""
    r, l_ = P_R * k, P_L * k
    c = s / (2 * r) + (r**2 - l_**2) / (2 * r * s)
    c1 = 1 / (2 * r) - (r**2 - l_**2) / (2 * r * s**2)
    c2 = (r**2 - l_**2) / (r * s**3)
    q = 1 - c**2
    return -c1 / np.sqrt(q), -(c2 * q + c * c1**2) / q**1.5


def cylinder_closed(s, k=1.0):
    """Closed form of cylinder_boom: the boom angle from the triangle O, C, B (|OB| = 0.8,
    |CB| = s, B left of O -> C), barrel and rod along C -> B."""
    s = np.asarray(s, dtype=float)
    c = C_C * k
    oc = math.hypot(*c)
    ob = C_OB * k
    at_o = np.arccos((ob**2 + oc**2 - s**2) / (2 * ob * oc))
    th1 = math.atan2(c[1], c[0]) + at_o          # left of O -> C: counter-clockwise from OC
    e1 = np.stack([np.cos(th1), np.sin(th1)], axis=-1)
    B = ob * e1
    th2 = np.arctan2(B[..., 1] - c[1], B[..., 0] - c[0])
    u = np.stack([np.cos(th2), np.sin(th2)], axis=-1)
    T, S1 = C_OT * k * e1, C_OS1 * k * e1
    S2, S3 = c + C_S2 * k * u, B - C_S3 * k * u
    out = {"1.theta": th1, "2.theta": th2, "3.theta": th2}
    for name, p in (("B", B), ("T", T), ("S1", S1), ("S2", S2), ("S3", S3)):
        out[f"{name}.x"], out[f"{name}.y"] = p[..., 0], p[..., 1]
    return out


def fd(f, s, h):
    """First and second derivatives of f (a dict of arrays) at s by five-point central differences."""
    vals = [f(s + j * h) for j in (-2, -1, 0, 1, 2)]
    d1 = {q: (vals[0][q] - 8 * vals[1][q] + 8 * vals[3][q] - vals[4][q]) / (12 * h) for q in vals[2]}
    d2 = {q: (-vals[0][q] + 16 * vals[1][q] - 30 * vals[2][q] + 16 * vals[3][q] - vals[4][q]) / (12 * h * h)
          for q in vals[2]}
    return d1, d2


def library_positions(mech, quantities):
    """The library's positions (order 0) as a function of s, for finite differences."""
    def f(s):
        motion = linkage.analyze(mech, s, order=0)
        return {q: motion.quantity(q)[0] for q in quantities}
    return f


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def assert_close(got, want, rel, label=""):
    """|got - want| <= rel * max(|want|, 1e-3 * max |want|, tiny) elementwise."""
    got, want = np.asarray(got, float), np.asarray(want, float)
    floor = max(1e-3 * float(np.max(np.abs(want))), 1e-300)
    err = np.abs(got - want) / np.maximum(np.abs(want), floor)
    assert np.all(err <= rel), f"{label}: worst relative error {np.max(err):.3g} at index {int(np.argmax(err))}"


S_PISTON = np.linspace(0.48, 0.32, 17)
S_CYL = np.linspace(0.6, 1.3, 15)


@pytest.fixture(scope="module")
def piston():
    return linkage.load("piston_driven_crank")


@pytest.fixture(scope="module")
def cylinder():
    return linkage.load("cylinder_boom")


# ----------------------------------------------------------------------------------------------
# 1. piston_driven_crank: closed-form kinematics
# ----------------------------------------------------------------------------------------------


def test_scaled_copies_are_the_shipped_schemes(piston, cylinder):
    """The scheme texts of this file (used for the scaling and stroke checks) are the shipped
    schemes: same declared stroke and same positions."""
    assert piston.input_range == pytest.approx((0.48, 0.32), abs=0)
    assert cylinder.input_range == pytest.approx((0.6, 1.3), abs=0)
    for shipped, text, s in ((piston, piston_text(), S_PISTON), (cylinder, cylinder_text(), S_CYL)):
        a, b = linkage.analyze(shipped, s), linkage.analyze(linkage.loads(text), s)
        for q in ("1.theta", "2.theta"):
            np.testing.assert_allclose(b.quantity(q)[0], a.quantity(q)[0], rtol=0, atol=1e-14)


def test_piston_positions_closed_form(piston):
    motion = linkage.analyze(piston, S_PISTON, order=0)
    assert np.all(motion.status == 0)
    want = piston_closed(S_PISTON)
    size = P_L + P_R
    for q in ("A.x", "A.y", "B.x", "B.y", "S2.x", "S2.y"):
        np.testing.assert_allclose(motion.quantity(q)[0], want[q], rtol=0, atol=1e-12 * size, err_msg=q)
    np.testing.assert_allclose(motion.point("O"), 0.0, atol=0)
    for q in ("1.theta", "2.theta"):
        np.testing.assert_allclose(wrap(motion.quantity(q)[0] - want[q]), 0.0, rtol=0, atol=1e-12, err_msg=q)
    # the slide is the input itself: the pair's K.s and its analogs 1, 0
    s, s1, s2 = linkage.analyze(piston, S_PISTON).quantity("slide.s")
    np.testing.assert_allclose(s, S_PISTON, atol=1e-15)
    np.testing.assert_allclose(s1, 1.0, atol=1e-12)
    np.testing.assert_allclose(s2, 0.0, atol=1e-9)


def test_piston_analogs_against_finite_differences(piston):
    quantities = ("1.theta", "2.theta", "A.x", "A.y", "S2.x", "S2.y")
    motion = linkage.analyze(piston, S_PISTON, order=2)
    h = 1e-4
    cf1, cf2 = fd(piston_closed, S_PISTON, h)
    lib1, lib2 = fd(library_positions(piston, quantities), S_PISTON, h)
    ex1, ex2 = piston_exact_analogs(S_PISTON)
    for q in quantities:
        _, d1, d2 = motion.quantity(q)
        assert_close(d1, cf1[q], 1e-7, f"{q}' vs closed form")
        assert_close(d2, cf2[q], 1e-6, f"{q}'' vs closed form")
        assert_close(d1, lib1[q], 1e-7, f"{q}' vs the library's positions")
        assert_close(d2, lib2[q], 1e-6, f"{q}'' vs the library's positions")
    _, d1, d2 = motion.quantity("1.theta")
    assert_close(d1, ex1, 1e-9, "1.theta' vs exact")
    assert_close(d2, ex2, 1e-8, "1.theta'' vs exact")


def test_piston_status_ok_over_the_declared_stroke(piston):
    s = np.linspace(*piston.input_range, 401)
    motion = linkage.analyze(piston, s, order=2, on_failure="mask")
    assert np.all(motion.status == 0)
    assert np.all(motion.error_bound <= 1e-8)
    assert np.all(np.diff(s) < 0)                        # the stroke runs towards O as declared
    assert np.all(np.isfinite(motion.quantity("1.theta")[2]))


def test_piston_columns_name_the_slide(piston, capsys):
    motion = linkage.analyze(piston, S_PISTON)
    cols = motion.columns()
    names = list(cols)
    assert names[:2] == ["i", "s"] and "phi_deg" not in cols
    np.testing.assert_array_equal(cols["s"], S_PISTON)      # the slide in m, not degrees travelled
    for q in ("1.theta'", "1.theta''", "A.x'", "A.y''", "slide.s", "slide.s'"):
        assert q in cols
    want = piston_closed(S_PISTON)
    np.testing.assert_allclose(cols["1.theta"], want["1.theta"], atol=1e-12)   # already in (-pi, pi]

    # the CLI: CSV columns and the units of the table for people and of JSON
    code, out, err = run(capsys, "analyze", "piston_driven_crank", "--format", "csv")
    assert code == 0, err
    table = read_csv(out)
    assert list(table)[:2] == ["i", "s"]
    s = table["s"]
    np.testing.assert_allclose(s, np.linspace(0.48, 0.32, len(s)), atol=1e-15)
    closed = piston_closed(s)
    for q in ("1.theta", "2.theta", "A.x", "A.y", "S2.y"):
        np.testing.assert_allclose(table[q], closed[q], atol=1e-12, err_msg=q)
    ex1, ex2 = piston_exact_analogs(s)
    assert_close(table["1.theta'"], ex1, 1e-9, "CSV 1.theta'")
    assert_close(table["1.theta''"], ex2, 1e-8, "CSV 1.theta''")

    code, out, err = run(capsys, "analyze", "piston_driven_crank", "--format", "json")
    assert code == 0, err
    units = json.loads(out)["units"]
    assert units["s"] == "m"
    assert units["1.theta'"] == "rad/m" and units["1.theta''"] == "rad/m^2"
    assert units["A.x'"] == "m/m" and units["A.x''"] == "m/m^2"

    code, out, err = run(capsys, "analyze", "piston_driven_crank", "--columns", "1.theta*,A.x*")
    assert code == 0, err
    header = [ln for ln in out.splitlines() if ln.strip() and not ln.startswith("#")][:2]
    names, units = header[0].split(), header[1].split()
    assert names[:2] == ["i", "s"]
    shown = dict(zip(names[1:], units))
    assert shown == {"s": "[m]", "1.theta": "[rad]", "1.theta'": "[rad/m]", "1.theta''": "[rad/m^2]",
                     "A.x": "[m]", "A.x'": "[m/m]", "A.x''": "[m/m^2]"}
    np.testing.assert_allclose(read_table(out)["s"], np.linspace(0.48, 0.32, 13), atol=1e-6)


def test_piston_json_header_does_not_show_the_slide_in_degrees(capsys):
    code, out, err = run(capsys, "analyze", "piston_driven_crank", "--format", "json")
    assert code == 0, err
    doc = json.loads(out)
    wrong = {k: v for k, v in doc.items() if k.endswith("_deg") and isinstance(v, float)
             and v == pytest.approx(math.degrees(0.48))}
    assert not wrong


def test_piston_cli_range_is_refused_naming_the_declared_stroke_in_m(capsys):
    """``--range A B`` gives a crank's input angles (deg): for a slide input the command refuses it
    (exit 2, nothing on stdout), naming the option and its values, the scheme, the input, and what
    to use instead: the stroke the scheme declares, ``range = [s_start, s_end]`` in m."""
    code, out, err = run(capsys, "analyze", "piston_driven_crank", "--range", "0.45", "0.35", "--format", "csv",
                         "-n", "4")
    assert code == 2 and out == "" and "Traceback" not in err, err
    assert ("--range 0.45 0.35: scheme 'piston_driven_crank' is driven by a slide (input '3'), analysed over the "
            "stroke it declares (range = [s_start, s_end] in m); --range A B gives input angles (deg) for a crank"
            ) in err, err


def test_piston_declared_range_is_a_stroke_in_m(capsys, tmp_path):
    """The stroke is chosen in the scheme instead: ``range = [0.45, 0.35]`` (m) gives the rows
    s = 0.45 .. 0.35 m in 4 steps (from the command line and the Python API), and the positions and
    analogs there are the closed form's."""
    text = shipped_text("piston_driven_crank")
    assert "range = [0.48, 0.32]" in text
    scheme = tmp_path / "piston_short_stroke.toml"
    scheme.write_text(text.replace("range = [0.48, 0.32]", "range = [0.45, 0.35]"), encoding="utf-8")
    code, out, err = run(capsys, "analyze", scheme, "--format", "csv", "-n", "4")
    assert code == 0, err
    table = read_csv(out)
    s_want = np.linspace(0.45, 0.35, 5)
    np.testing.assert_allclose(table["s"], s_want, rtol=0, atol=1e-15)
    closed = piston_closed(s_want)
    for q in ("1.theta", "2.theta", "A.x", "A.y", "S2.x", "S2.y"):
        np.testing.assert_allclose(table[q], closed[q], rtol=0, atol=1e-12, err_msg=q)
    ex1, ex2 = piston_exact_analogs(s_want)
    assert_close(table["1.theta'"], ex1, 1e-9, "CSV 1.theta'")
    assert_close(table["1.theta''"], ex2, 1e-8, "CSV 1.theta''")

    mech = linkage.load(scheme)
    assert mech.input_range == (0.45, 0.35)
    motion = linkage.analyze(mech, np.linspace(*mech.input_range, 5))
    assert np.all(motion.status == 0)
    np.testing.assert_allclose(motion.quantity("1.theta")[0], closed["1.theta"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(motion.quantity("A.y")[0], closed["A.y"], rtol=0, atol=1e-12)
    assert_close(motion.quantity("1.theta")[1], ex1, 1e-9, "1.theta' (Python API)")


# ----------------------------------------------------------------------------------------------
# 2. cylinder_boom: closed-form kinematics
# ----------------------------------------------------------------------------------------------


def test_cylinder_positions_closed_form(cylinder):
    motion = linkage.analyze(cylinder, S_CYL, order=0)
    assert np.all(motion.status == 0)
    want = cylinder_closed(S_CYL)
    for q in ("1.theta", "2.theta", "3.theta"):
        np.testing.assert_allclose(wrap(motion.quantity(q)[0] - want[q]), 0.0, atol=1e-10, err_msg=q)
    for p in ("B", "T", "S1", "S2", "S3"):
        for a in "xy":
            q = f"{p}.{a}"
            np.testing.assert_allclose(motion.quantity(q)[0], want[q], atol=1e-10 * C_OT, err_msg=q)
    np.testing.assert_allclose(motion.point("C"), np.tile(C_C, (len(S_CYL), 1)), atol=1e-15)
    # the cylinder's extension is the input: |CB| = s
    np.testing.assert_allclose(np.linalg.norm(motion.point("B") - C_C, axis=1), S_CYL, rtol=1e-12)
    ks = linkage.analyze(cylinder, S_CYL).quantity("K.s")
    np.testing.assert_allclose(np.abs(ks[0]), S_CYL, rtol=1e-12)
    np.testing.assert_allclose(np.abs(ks[1]), 1.0, rtol=1e-9)


def test_cylinder_analogs_against_finite_differences(cylinder):
    quantities = ("1.theta", "2.theta", "3.theta", "T.x", "T.y", "B.x", "B.y", "S2.x", "S2.y", "S3.x", "S3.y")
    motion = linkage.analyze(cylinder, S_CYL, order=2)
    h = 1e-3      # the cylinder's positions are smooth over the stroke: a larger step, less round-off
    cf1, cf2 = fd(cylinder_closed, S_CYL, h)
    # the traced mode of the Newton group exists only over the declared stroke: the library's own
    # positions are differenced at the inner positions (test_cylinder_assembles_beyond_the_stroke)
    inner = slice(1, -1)
    lib1, lib2 = fd(library_positions(cylinder, quantities), S_CYL[inner], h)
    for q in quantities:
        _, d1, d2 = motion.quantity(q)
        assert_close(d1, cf1[q], 1e-7, f"{q}' vs closed form")
        assert_close(d2, cf2[q], 1e-6, f"{q}'' vs closed form")
        assert_close(d1[inner], lib1[q], 1e-7, f"{q}' vs the library's positions")
        assert_close(d2[inner], lib2[q], 1e-6, f"{q}'' vs the library's positions")


def test_cylinder_beyond_the_traced_stroke_is_refused_saying_why(cylinder):
    """The group is solved by Newton's method from the mode traced over the declared stroke; the
    triangle O, C, B still closes just outside it (0.079 < s < 1.521 m), so the refusal must not
    say that the mechanism cannot be assembled there, but that the positions lie outside the
    traced range -- and the positions inside are solved as usual."""
    s = np.array([0.59, 0.7, 1.31])
    with pytest.raises(AssemblyError) as info:
        linkage.analyze(cylinder, s, order=1)
    text = str(info.value)
    assert "0.59, 1.31 outside the range 0.6 .. 1.3 m" in text and "II(1,2,3)" in text, text
    assert "cannot be assembled" not in text, text
    motion = linkage.analyze(cylinder, s, order=1, on_failure="mask")
    np.testing.assert_array_equal(motion.status, [-1, 0, -1])
    np.testing.assert_allclose(wrap(motion.quantity("1.theta")[0][1] - cylinder_closed(s[1:2])["1.theta"]), 0.0,
                               atol=1e-10)


def test_cylinder_status_ok_over_the_declared_stroke(cylinder):
    s = np.linspace(*cylinder.input_range, 301)
    motion = linkage.analyze(cylinder, s, order=2, on_failure="mask")
    assert np.all(motion.status == 0)
    assert np.all(motion.error_bound <= 1e-8)
    cols = motion.columns()
    assert list(cols)[:2] == ["i", "s"]
    np.testing.assert_array_equal(cols["s"], s)
    # the boom rises over the extending stroke (T.y grows: output start "min")
    assert np.all(np.diff(cylinder_closed(s)["T.y"]) > 0)


# ----------------------------------------------------------------------------------------------
# 3. the balancing force by virtual work
# ----------------------------------------------------------------------------------------------


def piston_potential(s):
    """V(s), J: gravity's potential (the crank's centre of mass is O, fixed) minus the work of the
    crank's constant moment."""
    q = piston_closed(s)
    return {"V": G * (P_MASS["2"] * q["S2.y"] + P_MASS["3"] * q["B.y"]) - P_MOMENT * q["1.theta"]}


def cylinder_potential(s):
    """V(s), J: gravity's potential minus the work of the payload at T."""
    q = cylinder_closed(s)
    return {"V": G * (C_MASS["1"] * q["S1.y"] + C_MASS["2"] * q["S2.y"] + C_MASS["3"] * q["S3.y"])
            - C_PAYLOAD * q["T.y"]}


@pytest.mark.parametrize("scheme, s, potential", [
    ("piston_driven_crank", S_PISTON, piston_potential),
    ("cylinder_boom", S_CYL, cylinder_potential),
])
def test_balancing_force_is_the_derivative_of_the_potential(scheme, s, potential):
    """Virtual work of a static position: F_b ds = dV, whatever the reactions."""
    mech = linkage.load(scheme)
    reactions = solve_reactions(linkage.analyze(mech, s))
    dv, _ = fd(potential, s, 1e-4)
    assert_close(reactions.balancing_moment, dv["V"], 1e-6, f"{scheme} balancing force")
    cols = reactions.columns()
    assert "balancing_force" in cols and "balancing_moment" not in cols
    np.testing.assert_array_equal(cols["s"], s)
    np.testing.assert_array_equal(cols["balancing_force"], reactions.balancing_moment)


@pytest.mark.parametrize("scheme, s", [("piston_driven_crank", S_PISTON), ("cylinder_boom", S_CYL)])
def test_virtual_power_residual_with_inertia(scheme, s):
    mech = linkage.load(scheme)
    omega = np.linspace(-1.5, 2.0, len(s))           # m/s
    eps = np.linspace(30.0, -20.0, len(s))           # m/s^2
    reactions = solve_reactions(linkage.analyze(mech, s, omega=omega, eps=eps))
    residual = virtual_power_residual(reactions)
    assert np.all(residual < 1e-9), residual.max()
    # inertia matters here: the balancing force differs from the static one
    static = solve_reactions(linkage.analyze(mech, s)).balancing_moment
    assert np.max(np.abs(reactions.balancing_moment - static)) > 1.0


# ----------------------------------------------------------------------------------------------
# 4. dynamics of a stroke
# ----------------------------------------------------------------------------------------------


def free_piston_builder(mass, stroke=None):
    """The slider-crank of piston_driven_crank by MechanismBuilder: only the piston has mass, no
    loads; ``stroke``: the declared range (m), or none."""
    b = linkage.MechanismBuilder("free_piston")
    b.link("0", points={"O": (0.0, 0.0)}, guides={"slide": {"through": (0.0, 0.0), "angle_deg": 0.0}})
    b.link("1", line=("O", "A"), length=P_R)
    b.link("2", line=("A", "B"), length=P_L)
    b.link("3", points={"B": (0.0, 0.0)}, mass=mass, com="B")
    b.revolute("O", "0", "1").revolute("A", "1", "2").revolute("B", "2", "3")
    b.prismatic("slide", "0", "3", guide="slide", at="B")
    b.inputs("3").assembly("A", left_of=("O", "B"))
    if stroke is not None:
        b.input_range(*stroke)
    return b


@pytest.mark.parametrize("stroke, force, v0, how", [((0.48, 0.32), -150.0, 0.3, "toml"),
                                                     ((0.32, 0.48), 80.0, 0.0, "builder")])
def test_stroke_of_a_free_piston_is_constant_acceleration(stroke, force, v0, how):
    """Only the piston has mass m, nothing but the constant force F acts: a = F / m,
    v^2 = v0^2 + 2 |F| |s - s0| / m, t = (|v| - v0) / |a|."""
    m = 2.5
    if how == "toml":
        mech = linkage.loads(piston_text(stroke=stroke, bare_mass=m))
    else:
        mech = free_piston_builder(m, stroke).build()
    motion = stroke_motion(mech, force, initial_speed=v0, positions=16)
    s0, s1 = stroke
    sense = np.sign(s1 - s0)
    np.testing.assert_allclose(motion.s, np.linspace(s0, s1, 17), atol=1e-15)
    speed = sense * np.sqrt(v0**2 + 2 * abs(force) * np.abs(motion.s - s0) / m)
    time = (np.abs(speed) - v0) / (abs(force) / m)
    np.testing.assert_allclose(motion.speed, speed, rtol=1e-6)
    np.testing.assert_allclose(motion.acceleration, force / m, rtol=1e-6)
    np.testing.assert_allclose(motion.t, time, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(motion.reduced.inertia, m, rtol=1e-9)
    np.testing.assert_allclose(motion.force, force)
    # the kinetostatics under this motion needs the actuator's force exactly
    np.testing.assert_allclose(motion.reactions().balancing_moment, force, rtol=1e-8)


def cylinder_reduced_mass(s):
    """sum m |r_S'|^2 + J theta'^2, kg, from the closed form's analogs."""
    d1, _ = fd(cylinder_closed, s, 1e-4)
    total = 0.0
    for link, com in (("1", "S1"), ("2", "S2"), ("3", "S3")):
        speed2 = d1[f"{com}.x"]**2 + d1[f"{com}.y"]**2
        total = total + C_MASS[link] * speed2 + C_INERTIA[link] * d1[f"{link}.theta"]**2
    return total


def test_cylinder_stroke_from_rest_energy_and_kinetostatics(cylinder):
    force = 9000.0
    motion = stroke_motion(cylinder, force, initial_speed=0.0)
    s = motion.s
    assert s[0] == 0.6 and s[-1] == pytest.approx(1.3, abs=1e-15)
    assert motion.speed[0] == 0 and np.all(motion.speed[1:] > 0)
    # the kinetostatics under the real motion needs exactly the actuator's force
    reactions = motion.reactions()
    np.testing.assert_allclose(reactions.balancing_moment, force, rtol=1e-8)
    np.testing.assert_allclose(motion.columns()["balancing_force"], force, rtol=1e-8)
    np.testing.assert_allclose(virtual_power_residual(reactions), 0.0, atol=1e-9)
    # reduced mass from the closed form, and the energy balance at every table position
    m_red = cylinder_reduced_mass(s)
    np.testing.assert_allclose(motion.reduced.inertia, m_red, rtol=1e-6)
    v = cylinder_potential(s)["V"]
    work = force * (s - s[0]) - (v - v[0])
    kinetic = 0.5 * m_red * motion.speed**2
    np.testing.assert_allclose(kinetic[1:], work[1:], rtol=1e-5)
    np.testing.assert_allclose(kinetic[-1], work[-1], rtol=1e-5)
    # the reduced force of the loads is -dV/ds
    dv, _ = fd(cylinder_potential, s, 1e-4)
    assert_close(motion.columns()["reduced_force"], -dv["V"], 1e-6, "reduced force")


# ----------------------------------------------------------------------------------------------
# 5. edges
# ----------------------------------------------------------------------------------------------


def shipped_text(name):
    return (ROOT / "schemes" / f"{name}.toml").read_text()


def test_slide_input_needs_a_range():
    for name, inp, old in (("piston_driven_crank", "3", "range = [0.48, 0.32]"),
                           ("cylinder_boom", "K", "range = [0.6, 1.3]")):
        text = shipped_text(name)
        assert old in text
        with pytest.raises(SchemeError) as info:
            linkage.loads(text.replace(old, ""))
        msg = str(info.value)
        assert f"'{inp}'" in msg and "range" in msg and "m" in msg
    with pytest.raises(SchemeError) as info:
        free_piston_builder(1.0).build()
    assert "'3'" in str(info.value) and "range" in str(info.value)


def test_slide_input_refuses_range_deg():
    text = shipped_text("piston_driven_crank").replace("range = [0.48, 0.32]", "range_deg = [10, 20]")
    with pytest.raises(SchemeError) as info:
        linkage.loads(text)
    assert "range_deg" in str(info.value) and "'3'" in str(info.value)
    with pytest.raises(SchemeError) as info:
        free_piston_builder(1.0).input_range(10.0, 20.0, degrees=True).build()
    assert "range_deg" in str(info.value) and "'3'" in str(info.value)
    assert free_piston_builder(1.0, (0.48, 0.32)).build().input_range == (0.48, 0.32)


def test_stroke_beyond_assembly_is_refused_naming_the_slides():
    text = shipped_text("piston_driven_crank").replace("range = [0.48, 0.32]", "range = [0.45, 0.6]")
    with pytest.raises(SchemeError) as info:
        linkage.loads(text)
    msg = str(info.value)
    assert "s = 0.5" in msg and " m" in msg and "0.6" in msg and "deg" not in msg
    # the cylinder cannot reach beyond |OC| + |OB| = 1.521 m
    text = shipped_text("cylinder_boom").replace("range = [0.6, 1.3]", "range = [0.6, 1.6]")
    with pytest.raises(SchemeError) as info:
        linkage.loads(text)
    msg = str(info.value)
    assert "1.6 m" in msg and "deg" not in msg
    reach = C_OB + math.hypot(*C_C)
    # the first refused slide is the reach, to the check's sampling
    found = [float(w) for w in msg.replace("..", " ").replace(",", " ").split() if _is_float(w)]
    step = 1.0 / 360                                  # the load-time check samples the stroke at 361 positions
    assert any(reach - step < v < reach + step for v in found), msg


def _is_float(word):
    try:
        float(word)
    except ValueError:
        return False
    return True


def test_stroke_that_cannot_reach_the_end_names_where_it_stops(cylinder):
    # from rest: the loads' reduced force at s = 0.6 (-dV/ds) exceeds a 1000 N push
    dv, _ = fd(cylinder_potential, np.array([0.6]), 1e-4)
    assert dv["V"][0] > 1000.0
    with pytest.raises(DynamicsError) as info:
        stroke_motion(cylinder, 1000.0)
    msg = str(info.value)
    assert "stops at s = 0.6" in msg and "m" in msg
    # with a start speed it runs a while: the stop is where the kinetic energy is used up
    with pytest.raises(DynamicsError) as info:
        stroke_motion(cylinder, 6000.0, initial_speed=0.5)
    msg = str(info.value)
    from scipy.optimize import brentq

    kinetic0, v0 = 0.5 * cylinder_reduced_mass(np.array([0.6]))[0] * 0.25, cylinder_potential(np.array([0.6]))["V"][0]

    def energy(s):
        return kinetic0 + 6000.0 * (s - 0.6) - (cylinder_potential(np.asarray(s, float))["V"] - v0)

    grid = np.linspace(0.6, 1.3, 701)
    k = np.flatnonzero(energy(grid) < 0)[0]
    stop = brentq(lambda s: float(energy(np.array([s]))[0]), grid[k - 1], grid[k], xtol=1e-12)
    found = float(msg.split("stops at s = ")[1].split()[0])
    assert found == pytest.approx(stop, abs=2e-6), (stop, msg)      # the exact stop, printed to 6 digits


def test_stroke_motion_refuses_a_crank():
    with pytest.raises(DynamicsInputError) as info:
        stroke_motion(linkage.load("four_bar"), 10.0)
    assert "crank" in str(info.value)


def test_dead_centre_is_singular_not_silently_wrong():
    # a declared stroke ending 5e-7 m short of the dead centre s = 0.5 m
    mech = linkage.loads(shipped_text("piston_driven_crank").replace("range = [0.48, 0.32]",
                                                                      "range = [0.32, 0.4999995]"))
    s = np.array([0.499, 0.4999, 0.49999, 0.499999, 0.4999995, 0.4999999, 0.5 - 1e-9, 0.5 - 1e-12, 0.5])
    motion = linkage.analyze(mech, s, order=2, on_failure="mask")
    assert set(motion.status.tolist()) <= {0, -2}
    assert motion.status[-1] == -2                      # the dead centre itself
    ok = motion.status == 0
    ex1, ex2 = piston_exact_analogs(s[ok])
    _, d1, d2 = motion.quantity("1.theta")
    assert_close(d1[ok], ex1, 1e-8, "theta' where status OK")
    assert_close(d2[ok], ex2, 1e-6, "theta'' where status OK")
    assert np.all(np.isnan(d1[~ok]))
    with pytest.raises(AssemblyError) as info:
        linkage.analyze(mech, s)
    assert "0.5" in str(info.value) and "m" in str(info.value)
    # over the declared stroke: OK where the analogs are right, never a silent OK near 0.5
    s = np.linspace(*mech.input_range, 41)
    motion = linkage.analyze(mech, s, order=2, on_failure="mask")
    ok = motion.status == 0
    ex1, ex2 = piston_exact_analogs(s[ok])
    _, d1, d2 = motion.quantity("1.theta")
    assert_close(d1[ok], ex1, 1e-8, "theta' over the stroke")
    assert_close(d2[ok], ex2, 1e-6, "theta'' over the stroke")


@pytest.mark.parametrize("k", [1e-3, 1e3])
@pytest.mark.parametrize("scheme", ["piston"])    # the cylinder: tests/test_structure.py::test_scale_invariance
def test_scale_invariance(scheme, k):
    text, closed, s = (piston_text, piston_closed, S_PISTON) if scheme == "piston" else \
        (cylinder_text, cylinder_closed, S_CYL)
    base = linkage.analyze(linkage.loads(text()), s)
    scaled_mech = linkage.loads(text(k))
    assert scaled_mech.input_range == pytest.approx(tuple(k * v for v in linkage.loads(text()).input_range))
    scaled = linkage.analyze(scaled_mech, k * s)
    assert np.all(scaled.status == 0)
    want = closed(k * s, k)
    for q in ("1.theta", "2.theta"):
        a, b = base.quantity(q), scaled.quantity(q)
        np.testing.assert_allclose(wrap(b[0] - a[0]), 0.0, atol=1e-12, err_msg=q)
        np.testing.assert_allclose(wrap(b[0] - want[q]), 0.0, atol=1e-10, err_msg=q)
        np.testing.assert_allclose(b[1] * k, a[1], rtol=1e-9, atol=1e-12, err_msg=q + "'")
        np.testing.assert_allclose(b[2] * k**2, a[2], rtol=1e-8, atol=1e-10, err_msg=q + "''")
    point = "A" if scheme == "piston" else "T"
    for a_ in "xy":
        q = f"{point}.{a_}"
        a, b = base.quantity(q), scaled.quantity(q)
        np.testing.assert_allclose(b[0] / k, a[0], rtol=1e-12, atol=1e-14, err_msg=q)
        np.testing.assert_allclose(b[0] / k, want[q] / k, rtol=1e-10, atol=1e-12, err_msg=q)
        np.testing.assert_allclose(b[1], a[1], rtol=1e-9, atol=1e-12, err_msg=q + "'")
        np.testing.assert_allclose(b[2] * k, a[2], rtol=1e-8, atol=1e-10, err_msg=q + "''")


# ----------------------------------------------------------------------------------------------
# two cylinders (W = 2): each cylinder's balancing force is the generalized force of its slide
# ----------------------------------------------------------------------------------------------

EXCAVATOR = """
name = "excavator"
inputs = ["K1", "K2"]
range = [0.6, 1.2]
[input_laws.K2]
ratio = -0.5
phase = 1.3

[links.0]
points = { O = [0.0, 0.0], C = [0.6, -0.4] }
[links.1]
line = ["O", "T"]
length = 2.0
points.B = { from = "O", distance = 0.8 }
points.E = { from = "O", distance = 1.2 }
mass = 50.0
com = "T"
[links.2]
points = { C = [0.0, 0.0] }
guides.axis = { through = [0.0, 0.0], angle_deg = 0 }
mass = 5.0
com = "C"
[links.3]
points = { B = [0.0, 0.0] }
mass = 3.0
com = "B"
[links.4]
line = ["T", "F"]
length = 0.4
points.G = { from = "T", distance = 1.2, angle_deg = 180 }
mass = 20.0
com = "G"
[links.5]
points = { E = [0.0, 0.0] }
guides.axis = { through = [0.0, 0.0], angle_deg = 0 }
mass = 3.0
com = "E"
[links.6]
points = { F = [0.0, 0.0] }
mass = 2.0
com = "F"
[pairs.O]
links = ["0", "1"]
[pairs.C]
links = ["0", "2"]
[pairs.B]
links = ["1", "3"]
[pairs.K1]
kind = "P"
links = ["2", "3"]
guide = "axis"
at = "B"
[pairs.T]
links = ["1", "4"]
[pairs.E]
links = ["1", "5"]
[pairs.F]
links = ["4", "6"]
[pairs.K2]
kind = "P"
links = ["5", "6"]
guide = "axis"
at = "F"
[assembly.B]
left_of = ["O", "C"]
[assembly.F]
left_of = ["E", "T"]
[loads]
gravity = [0.0, -9.81]
"""


def _potential(mech, s1, s2: float) -> np.ndarray:
    """Gravity's potential energy, J, with the first cylinder at the slides ``s1`` (m, an array)
    and the second at ``s2`` (m), held there by a law of zero ratio, so each slide can be varied
    alone (the mode traced over the declared stroke, as in the two-input mechanism)."""
    held = mech.with_input_laws(K2=linkage.InputLaw(ratio=0.0, phase=s2))
    motion = linkage.analyze(held, np.asarray(s1, float), order=0)
    return sum(link.mass * 9.81 * (motion.poses[name][:, 1] + motion.arm(name, link.center_of_mass)[:, 1])
               for name, link in held.links.items() if name != held.frame)


def test_two_cylinders_each_balance_the_generalized_force_of_their_own_slide():
    """An excavator arm with two cylinders (the second's slide a law of the first's): statically,
    each balancing force equals dV/ds_k of gravity's potential energy with the other slide held
    (central differences), and the tables name both (balancing_force, balancing_force.K2)."""
    mech = linkage.loads(EXCAVATOR)
    assert linkage.structure_of(mech).formula == "I(K1) → I(K2) → II(1,2,3) → II(4,5,6)"
    s1, h = 0.9, 1e-5
    s2 = -0.5 * s1 + 1.3
    columns = solve_reactions(linkage.analyze(mech, np.array([s1]))).columns()
    below, above = _potential(mech, [s1 - h, s1 + h], s2)
    d1 = (above - below) / (2 * h)
    d2 = float(_potential(mech, [s1], s2 + h)[0] - _potential(mech, [s1], s2 - h)[0]) / (2 * h)
    assert columns["balancing_force"][0] == pytest.approx(d1, rel=1e-7)
    assert columns["balancing_force.K2"][0] == pytest.approx(d2, rel=1e-7)
    assert abs(d1) > 100 and abs(d2) > 100          # both cylinders carry a load here
