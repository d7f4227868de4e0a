"""``linkage forces`` and ``linkage dynamics`` on the command line, checked against independent oracles.

The oracles are written here from the textbook: the slider-crank's closed-form kinematics with
analytic first and second analogs, the course's group-by-group force analysis of the RRP dyad and
the crank, statics of the four-bar by virtual work (finite differences of its closed-form
positions), and Mertsalov's flywheel method (docs/methods.md). No number compared here is
copied from the library's output; the only inputs taken from the output are the independent
variables of a row (phi_deg, the angle from position 1 in the direction of rotation, with the
start phi0) and, to close the loop, a row's own omega / eps / reduced moment
where the check is "the other columns follow from these".
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import linkage

SHIPPED = list(linkage.shipped_schemes())

# slider_crank.toml / course_slider_crank.toml: crank OA (mass at O, no J), rod AB (S2 0.0741 m
# from A), slider B on the guide y = e
L1, L2, E_OFF, A_S2 = 0.0742, 0.2225, 0.01335, 0.0741
M1, M2, J2, M3, G = 30.0, 400.0, 8.35, 500.0, 9.81
# course_slider_crank.toml [loads] and [dynamics]
CYCLE = np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -12321, -27142, -125000], float)
W_M, DELTA, I_0 = -10.472, 0.0556, 90.264 + 0.0  # the crank's own inertia about O is 0 (mass at O)
PHI0_DEG = math.degrees(math.asin(E_OFF / (L1 + L2)))  # far dead centre: crank and rod in line
# four_bar.toml: O = (0, 0), C = (0.3, 0), OA, AB, CB; S2 mid AB (3 kg), S3 mid CB (2 kg)
FB_OA, FB_AB, FB_CB, FB_C = 0.1, 0.3, 0.25, np.array([0.3, 0.0])
FB_M2, FB_M3 = 3.0, 2.0

DYNAMICS_KEYS = ("driving_moment", "required_constant_inertia", "flywheel_inertia", "delta_actual",
                 "dynamic_coefficient")
DYNAMICS_COLUMNS = ("phi_deg", "reduced_moment_resistance", "reduced_inertia",
                    "reduced_inertia_derivative", "omega", "eps", "balancing_moment")


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------


from _cli_io import read_csv, read_table, run  # noqa: E402


def json_doc(capsys, command, scheme, *options):
    code, out, err = run(capsys, command, scheme, "--format", "json", *options)
    assert code == 0, err
    doc = json.loads(out)
    cols = {name: np.array([np.nan if r[name] is None else r[name] for r in doc["rows"]], float)
            for name in doc["rows"][0]}
    return doc, cols, err


def close(actual, expected, rel=1e-9):
    """Equal to ``rel`` of the largest expected value (some entries are ~0)."""
    expected = np.asarray(expected, float)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rel * max(np.abs(expected).max(), 1e-300))


def trapezoid_cumulative(values, step):
    return np.concatenate([[0.0], np.cumsum((values[1:] + values[:-1]) / 2 * step)])


# ----------------------------------------------------------------------------------------------
# oracle 1: slider-crank kinematics, closed form with analytic analogs
# ----------------------------------------------------------------------------------------------


def slider_crank(phi):
    """Positions and first / second analogs (d/dphi) of the slider-crank, arrays over phi.

    l2 sin(theta) = e - l1 sin(phi), B right of A (cos(theta) > 0)."""
    phi = np.asarray(phi, float)
    s, c = np.sin(phi), np.cos(phi)
    st = (E_OFF - L1 * s) / L2
    ct = np.sqrt(1 - st**2)
    t1 = -L1 * c / (L2 * ct)                          # theta'
    t2 = (L1 * s + L2 * st * t1**2) / (L2 * ct)       # theta''
    u, n = np.stack([ct, st], -1), np.stack([-st, ct], -1)
    A = L1 * np.stack([c, s], -1)
    A1, A2 = L1 * np.stack([-s, c], -1), -A
    d1 = lambda r: r * t1[:, None] * n                # d/dphi of r u
    d2 = lambda r: r * (t2[:, None] * n - (t1**2)[:, None] * u)
    return {"A": A, "A1": A1, "A2": A2, "t1": t1, "t2": t2, "u": u,
            "B": A + L2 * u, "B1": A1 + d1(L2), "B2": A2 + d2(L2),
            "S": A + A_S2 * u, "S1": A1 + d1(A_S2), "S2": A2 + d2(A_S2)}


def test_the_slider_crank_oracle_itself():
    """The analytic analogs of the oracle against its own positions (five-point differences)."""
    phi, h = np.radians([17.0, 100.0, 200.0, 333.0]), 1e-3
    at = [slider_crank(phi + k * h) for k in (-2, -1, 0, 1, 2)]
    for key in ("B", "S"):
        p = [a[key] for a in at]
        d1 = (p[0] - 8 * p[1] + 8 * p[3] - p[4]) / (12 * h)
        d2 = (-p[0] + 16 * p[1] - 30 * p[2] + 16 * p[3] - p[4]) / (12 * h * h)
        np.testing.assert_allclose(at[2][key + "1"], d1, atol=1e-10)
        np.testing.assert_allclose(at[2][key + "2"], d2, atol=1e-7)
    np.testing.assert_allclose(at[2]["B"][:, 1], E_OFF, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(at[2]["B"] - at[2]["A"], axis=1), L2, atol=1e-15)


# ----------------------------------------------------------------------------------------------
# oracle 2: the course force analysis of the slider-crank (RRP dyad, then the crank)
# ----------------------------------------------------------------------------------------------


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def slider_crank_forces(phi, omega, eps, fx=0.0):
    """Reactions and balancing moment for crank speed ``omega`` / acceleration ``eps`` (arrays or
    numbers) and a force ``fx`` along x on the slider. Returns R[a, b] for each pair's
    ``links = [a, b]`` (O: [0, 1], A: [1, 2], B: [2, 3], slide: [0, 3]) and M_b."""
    k = slider_crank(phi)
    omega, eps = np.broadcast_to(omega, k["t1"].shape), np.broadcast_to(eps, k["t1"].shape)
    fx = np.broadcast_to(fx, k["t1"].shape)
    acc = lambda key: k[key + "2"] * (omega**2)[:, None] + k[key + "1"] * eps[:, None]
    F2 = -M2 * acc("S") + [0.0, -M2 * G]             # rod: inertia force + weight at S2
    Mi2 = -J2 * (k["t2"] * omega**2 + k["t1"] * eps)  # rod: inertia moment
    F3 = -M3 * acc("B")                              # slider: inertia force (along x) at B
    # slider: -R23 + N j + F3 + (fx, -m3 g) = 0, every force through B (moment of the guide 0)
    XB = fx + F3[:, 0]
    # rod, moments about A: (B - A) x R23 + (S2 - A) x F2 + Mi2 = 0 -> Y_B
    u = k["u"]
    YB = (L2 * u[:, 1] * XB - A_S2 * cross(u, F2) - Mi2) / (L2 * u[:, 0])
    R23 = np.stack([XB, YB], -1)                     # slider on rod
    R21 = -R23 - F2                                  # crank on rod
    N = YB + M3 * G - F3[:, 1]                       # guide on slider (normal, along y)
    Mb = cross(k["A"], R21)                          # crank: M_b + A x (-R21) = 0
    R10 = R21 + [0.0, M1 * G]                        # frame on crank (crank weight at O)
    return {"balancing_moment": Mb, "O": -R10, "A": -R21, "B": R23,
            "slide": np.stack([np.zeros_like(N), -N], -1), "slide.M": np.zeros_like(N)}


def check_slider_crank_reactions(cols, phi, omega, eps, fx, rel=1e-9):
    expected = slider_crank_forces(phi, omega, eps, fx)
    close(cols["balancing_moment"], expected["balancing_moment"], rel)
    for pair in ("O", "A", "B", "slide"):
        R = expected[pair]
        scale = np.abs(R).max()
        np.testing.assert_allclose(cols[f"{pair}.Rx"], R[:, 0], rtol=0, atol=rel * scale, err_msg=pair)
        np.testing.assert_allclose(cols[f"{pair}.Ry"], R[:, 1], rtol=0, atol=rel * scale, err_msg=pair)
    np.testing.assert_allclose(cols["slide.M"], 0.0, atol=1e-9)


# ----------------------------------------------------------------------------------------------
# oracle 3: four-bar positions (closed form) and statics by virtual work
# ----------------------------------------------------------------------------------------------


def four_bar(phi):
    """A, B of the four-bar: B on the circles (A, AB) and (C, CB), left of the line A -> C."""
    A = FB_OA * np.array([math.cos(phi), math.sin(phi)])
    d = np.linalg.norm(FB_C - A)
    w = (FB_C - A) / d
    along = (FB_AB**2 - FB_CB**2 + d**2) / (2 * d)
    across = math.sqrt(FB_AB**2 - along**2)
    return A, A + along * w + across * np.array([-w[1], w[0]])


def four_bar_static_moment(phi):
    """M_b = -sum(m g . r'_S) (virtual work, gravity only) with r'_S from five-point differences."""
    def potential_height(p):
        A, B = four_bar(p)
        return FB_M2 * (A[1] + B[1]) / 2 + FB_M3 * (FB_C[1] + B[1]) / 2  # sum m y_S

    h = 1e-3
    y = [potential_height(phi + k * h) for k in (-2, -1, 0, 1, 2)]
    dy = (y[0] - 8 * y[1] + 8 * y[3] - y[4]) / (12 * h)
    return -(-G) * dy  # g = (0, -9.81): -sum(m g_y y')


# ----------------------------------------------------------------------------------------------
# linkage forces: every shipped scheme, every format, the column contract
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("scheme", SHIPPED)
def test_forces_every_scheme_every_format(capsys, scheme):
    mech = linkage.load(scheme)
    pairs = sorted(mech.pairs)
    prismatic = {k for k, p in mech.pairs.items() if type(p).__name__ == "Prismatic"}
    code, out_csv, err_csv = run(capsys, "forces", scheme, "--format", "csv")
    assert code == 0, err_csv
    code, out_table, err_table = run(capsys, "forces", scheme)
    assert code == 0, err_table
    doc, full, err_json = json_doc(capsys, "forces", scheme)
    assert "Traceback" not in err_csv + err_table + err_json

    cols = read_csv(out_csv)
    crank = mech.coordinate.is_angle
    # a slide input: the position column is its slide s (m), balanced by a force (N)
    position, balancing = ("phi_deg", "balancing_moment") if crank else ("s", "balancing_force")
    expected = ["i", position, balancing] + [f"{balancing}.{k}" for k in mech.inputs[1:]]
    expected += [f"{k}.{c}" for k in pairs for c in ("R", "angle_deg")]
    # CSV and JSON: every column, the components (and K.M for prismatic pairs) too
    extra = [f"{k}.{c}" for k in pairs for c in ("Rx", "Ry")] + [f"{k}.M" for k in prismatic]
    assert sorted(cols) == sorted(expected + extra)
    assert list(cols)[:3] == ["i", position, balancing]
    n = (mech.extra.get("dynamics") or {}).get("positions", 12)  # the scheme's, else 12
    assert len(cols[position]) == n + 1
    if crank:
        np.testing.assert_allclose(cols["phi_deg"], 360.0 / n * np.arange(n + 1), rtol=0, atol=1e-9)
    else:   # n equal steps over the declared stroke, from its first end
        a, b = mech.input_range
        np.testing.assert_allclose(cols["s"], a + (b - a) * np.arange(n + 1) / n, rtol=0, atol=1e-12)
        assert doc["units"][balancing] == "N" and doc["units"]["s"] == "m"
    assert sorted(full) == sorted(expected + extra)
    for name in expected + extra:
        np.testing.assert_array_equal(full[name], cols[name], err_msg=name)
    for k in pairs:
        np.testing.assert_allclose(full[f"{k}.R"], np.hypot(full[f"{k}.Rx"], full[f"{k}.Ry"]),
                                   rtol=1e-14, atol=1e-12, err_msg=k)
        nonzero = full[f"{k}.R"] > 1e-9 * max(full[f"{k}.R"].max(), 1e-300)
        angle = np.degrees(np.arctan2(full[f"{k}.Ry"], full[f"{k}.Rx"]))
        gap = np.angle(np.exp(1j * np.radians(full[f"{k}.angle_deg"] - angle)))
        np.testing.assert_allclose(gap[nonzero], 0.0, atol=1e-12, err_msg=k)
    assert doc["scheme"] == mech.name
    assert doc["virtual_power_residual_max"] < 1e-9
    for k in pairs:  # directions in (-180, 180]
        assert np.all((full[f"{k}.angle_deg"] > -180) & (full[f"{k}.angle_deg"] <= 180)), k
    # table: the balancing moment and some reactions, the same numbers to the printed digits
    table = read_table(out_table)
    assert list(table)[:3] == ["i", position, balancing] and set(table) <= set(cols)
    assert max(len(ln) for ln in out_table.splitlines() if not ln.startswith("#")) <= 160
    for name in table:
        scale = np.abs(cols[name]).max()
        np.testing.assert_allclose(table[name], cols[name], rtol=1e-6, atol=1e-9 * scale, err_msg=name)
    assert any(ln.startswith("# virtual_power_residual_max") for ln in out_table.splitlines())
    # a scheme without a [dynamics] speed is analysed statically and says so on stderr
    if mech.extra.get("dynamics") is None:
        assert doc["omega"] is None
        for err in (err_csv, err_table, err_json):
            assert "linkage: note:" in err and "static analysis" in err
        assert any("static analysis" in n for n in doc["notes"])
    else:
        assert doc["omega"] is not None and "static" not in err_json


def test_forces_positions_option(capsys):
    doc, cols, _ = json_doc(capsys, "forces", "four_bar", "--positions", "6")
    assert len(doc["rows"]) == 7
    np.testing.assert_allclose(np.diff(cols["phi_deg"]), 60.0, atol=1e-9)
    assert doc["positions"] == 6


def test_forces_omega_and_rpm_are_exclusive(capsys):
    code, out, err = run(capsys, "forces", "slider_crank", "--omega", "1", "--rpm", "10")
    assert code == 2 and out == "" and "not allowed with" in err
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--omega", "1", "--rpm", "10")
    assert code == 2 and out == ""


def test_forces_rpm_60_is_omega_two_pi(capsys):
    doc_rpm, by_rpm, _ = json_doc(capsys, "forces", "four_bar", "--rpm", "60")
    doc_w, by_omega, _ = json_doc(capsys, "forces", "four_bar", "--omega", repr(2 * math.pi))
    assert doc_rpm["omega"] == pytest.approx(2 * math.pi, rel=1e-15)
    assert list(by_rpm) == list(by_omega)
    for name in by_rpm:
        np.testing.assert_allclose(by_rpm[name], by_omega[name], rtol=1e-12, atol=1e-12, err_msg=name)
    # and the speed matters: the static table differs
    _, static, _ = json_doc(capsys, "forces", "four_bar")
    assert np.abs(static["balancing_moment"] - by_rpm["balancing_moment"]).max() > 1e-3


def test_forces_four_bar_static_against_virtual_work(capsys):
    doc, cols, err = json_doc(capsys, "forces", "four_bar", "--positions", "24")
    assert doc["omega"] is None and "static analysis" in err
    assert doc["direction"] == 1  # no speed, no [dynamics]: counter-clockwise
    phi_abs = np.radians(doc["phi0_deg"] + cols["phi_deg"])
    expected = np.array([four_bar_static_moment(p) for p in phi_abs])
    np.testing.assert_allclose(cols["balancing_moment"], expected, rtol=0,
                               atol=1e-8 * np.abs(expected).max())
    # equilibrium of the whole mechanism: frame forces carry the weight (6 kg), moments about O
    # balance: M_b + C x R[3,0] + sum(S x G) = 0 (pair C links = [3, 0], pair O links = [0, 1])
    R_frame_on_crank = -np.stack([cols["O.Rx"], cols["O.Ry"]], -1)
    R_frame_on_rocker = np.stack([cols["C.Rx"], cols["C.Ry"]], -1)
    total = R_frame_on_crank + R_frame_on_rocker
    np.testing.assert_allclose(total, np.tile([0.0, 6.0 * G], (len(total), 1)), atol=1e-9)
    for k, phi in enumerate(phi_abs):
        A, B = four_bar(phi)
        moments = (cols["balancing_moment"][k] + cross(FB_C, R_frame_on_rocker[k])
                   + cross((A + B) / 2, np.array([0.0, -FB_M2 * G]))
                   + cross((FB_C + B) / 2, np.array([0.0, -FB_M3 * G])))
        assert abs(moments) < 1e-9


@pytest.mark.parametrize("omega, eps", [(-10.472, 0.0), (-10.472, 3.0), (0.0, 3.0), (25.0, -40.0)])
def test_forces_slider_crank_against_the_course_force_analysis(capsys, omega, eps):
    doc, cols, err = json_doc(capsys, "forces", "slider_crank", "--omega", repr(omega),
                              "--eps", repr(eps))
    assert doc["omega"] == omega and doc["eps"] == eps and doc["notes"] == []
    assert "static" not in err
    # rows: from the far dead centre in the sense of omega (CCW for 0: no [dynamics]), 30 deg steps
    sense = -1.0 if omega < 0 else 1.0
    np.testing.assert_allclose(cols["phi_deg"], 30.0 * np.arange(13), atol=1e-9)
    check_slider_crank_reactions(cols, np.radians(PHI0_DEG + sense * cols["phi_deg"]), omega, eps, 0.0)
    assert doc["virtual_power_residual_max"] < 1e-9


def test_forces_eps_without_a_speed_is_not_silently_dropped(capsys):
    """``--eps`` with no speed: the run uses the acceleration (inertia loads of omega = 0, eps = 3)
    and says so on stderr, instead of reporting eps = 3 over a static table: every reaction and
    the balancing moment are the closed form's at omega = 0, eps = 3, which differ from the static
    ones."""
    code, out, err = run(capsys, "forces", "slider_crank", "--eps", "3", "--format", "json")
    assert code == 0, err
    assert "no speed given: omega = 0 with the given eps" in err, err
    doc = json.loads(out)
    assert doc["omega"] == 0.0 and doc["eps"] == 3.0
    cols = {k: np.array([r[k] for r in doc["rows"]]) for k in doc["rows"][0]}
    phi = np.radians(PHI0_DEG + cols["phi_deg"])
    check_slider_crank_reactions(cols, phi, 0.0, 3.0, 0.0)
    static = slider_crank_forces(phi, 0.0, 0.0, 0.0)["balancing_moment"]
    assert np.max(np.abs(cols["balancing_moment"] - static)) > 1e-3 * np.max(np.abs(static))


def test_forces_course_scheme_uses_its_mean_speed_and_force_cycle(capsys):
    """No speed option: the scheme's mean speed; the useful resistance of the 13 cycle positions
    (position 13 carries the end-of-stroke value)."""
    doc, cols, err = json_doc(capsys, "forces", "course_slider_crank")
    assert doc["omega"] == W_M and doc["notes"] == [] and "static" not in err
    np.testing.assert_allclose(cols["phi_deg"], 30.0 * np.arange(13), atol=1e-9)
    check_slider_crank_reactions(cols, np.radians(PHI0_DEG - cols["phi_deg"]), W_M, 0.0, CYCLE)


def test_forces_course_scheme_between_the_cycle_positions(capsys):
    """24 positions: the cycle force is linear in the cycle angle between the 13 given values."""
    doc, cols, _ = json_doc(capsys, "forces", "course_slider_crank", "--positions", "24")
    assert len(doc["rows"]) == 25
    np.testing.assert_allclose(cols["phi_deg"], 15.0 * np.arange(25), atol=1e-9)
    force = np.interp(15.0 * np.arange(25), 30.0 * np.arange(13), CYCLE)
    check_slider_crank_reactions(cols, np.radians(PHI0_DEG - cols["phi_deg"]), W_M, 0.0, force)


# ----------------------------------------------------------------------------------------------
# linkage dynamics: the course method against Mertsalov's method written here
# ----------------------------------------------------------------------------------------------


def mertsalov(rows_moment, delta, mean_speed=W_M, i_0=I_0):
    """The course method from the reduced moment of resistance at the 13 positions (rows) and the
    closed-form I''(psi): driving moment, Delta T', I', flywheel, omega, eps."""
    phi = np.radians(PHI0_DEG - 30.0 * np.arange(13))
    k = slider_crank(phi)
    s, wm = np.sign(mean_speed), abs(mean_speed)
    variable = M2 * np.sum(k["S1"] ** 2, 1) + J2 * k["t1"] ** 2 + M3 * k["B1"][:, 0] ** 2
    derivative = 2 * s * (M2 * np.sum(k["S1"] * k["S2"], 1) + J2 * k["t1"] * k["t2"]
                          + M3 * k["B1"][:, 0] * k["B2"][:, 0])
    step = 2 * math.pi / 12
    psi = step * np.arange(13)
    work = trapezoid_cumulative(rows_moment, step)          # A_c(psi)
    driving = -work[-1] / (2 * math.pi)                     # M_d
    dT1 = driving * psi + work - variable * wm**2 / 2       # Delta T' = Delta T - T''
    swing = dT1.max() - dT1.min()
    required = swing / (delta * wm**2)                      # I'
    constant = max(required, i_0)
    T1 = constant * wm**2 / 2 + dT1 - (dT1.max() + dT1.min()) / 2
    omega = s * np.sqrt(2 * T1 / constant)
    eps = s * (driving + rows_moment - derivative * omega**2 / 2) / (constant + variable)
    return {"phi": phi, "variable": variable, "derivative": derivative, "driving": driving,
            "required": required, "flywheel": required - i_0, "swing": swing, "constant": constant,
            "omega": omega, "eps": eps}


def reduced_resistance(phi):
    """M_c = s (F x_B' + m2 g . r'_S2) with the course force cycle (the slider's weight does no
    work: y_B' = 0)."""
    k = slider_crank(phi)
    return np.sign(W_M) * (CYCLE * k["B1"][:, 0] - M2 * G * k["S1"][:, 1])


def test_dynamics_course_slider_crank_against_mertsalov(capsys):
    doc, cols, err = json_doc(capsys, "dynamics", "course_slider_crank")
    assert "Traceback" not in err
    for key in DYNAMICS_KEYS:
        assert key in doc, key
    for name in DYNAMICS_COLUMNS:
        assert name in cols, name
    assert len(doc["rows"]) == 13
    # rows start at the far dead centre and go clockwise; phi_deg counts the angle travelled
    np.testing.assert_allclose(cols["phi_deg"], 30.0 * np.arange(13), atol=1e-9)
    np.testing.assert_array_equal(cols["i"], np.arange(1, 14))
    phi = np.radians(PHI0_DEG - cols["phi_deg"])
    # the reduced moment of resistance and the reduced inertia from the closed form
    close(cols["reduced_moment_resistance"], reduced_resistance(phi))
    ref = mertsalov(cols["reduced_moment_resistance"], DELTA)
    close(cols["reduced_inertia_derivative"], ref["derivative"])
    # reduced_inertia = the machine as declared: I_0 + I''(psi) (the flywheel is reported apart)
    close(cols["reduced_inertia"] - ref["variable"], np.full(13, I_0))
    # driving moment, I', flywheel, delta
    assert doc["driving_moment"] == pytest.approx(ref["driving"], rel=1e-9)
    assert doc["driving_moment"] > 0  # a working machine: the motor drives
    assert doc["required_constant_inertia"] == pytest.approx(ref["required"], rel=1e-9)
    assert ref["flywheel"] > 0
    assert doc["flywheel_inertia"] == pytest.approx(ref["flywheel"], rel=1e-9)
    assert doc["delta_actual"] == pytest.approx(DELTA, rel=1e-12)
    # law of motion
    close(cols["omega"], ref["omega"])
    assert np.all(cols["omega"] < 0)  # clockwise
    close(cols["eps"], ref["eps"], rel=1e-8)
    w = np.abs(cols["omega"])
    assert (w.max() - w.min()) / ((w.max() + w.min()) / 2) == pytest.approx(DELTA, rel=1e-2)
    # kinetostatics under the real motion: the course force analysis with the rows' omega, eps
    expected = slider_crank_forces(phi, cols["omega"], cols["eps"], CYCLE)["balancing_moment"]
    close(cols["balancing_moment"], expected)
    assert doc["dynamic_coefficient"] == pytest.approx(
        np.abs(cols["balancing_moment"]).max() / abs(ref["driving"]), rel=1e-9)


def test_dynamics_no_flywheel_needed_with_a_large_delta(capsys):
    doc, cols, _ = json_doc(capsys, "dynamics", "course_slider_crank", "--delta", "1.9")
    ref = mertsalov(cols["reduced_moment_resistance"], 1.9)
    assert ref["required"] < I_0
    assert doc["flywheel_inertia"] is None
    assert doc["required_constant_inertia"] == pytest.approx(ref["required"], rel=1e-9)
    # the actual delta with the declared inertia alone: Delta T'_ab / (I_0 omega_m^2)
    assert doc["delta_actual"] == pytest.approx(ref["swing"] / (I_0 * W_M**2), rel=1e-9)
    close(cols["reduced_inertia"], I_0 + ref["variable"])
    close(cols["omega"], ref["omega"])
    close(cols["eps"], ref["eps"], rel=1e-8)
    assert doc["dynamic_coefficient"] == pytest.approx(
        np.abs(cols["balancing_moment"]).max() / abs(doc["driving_moment"]), rel=1e-12)
    # the table says so in words
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--delta", "1.9")
    assert code == 0, err
    assert "# flywheel_inertia: none needed" in out.splitlines()


def test_dynamics_table_prints_the_summary_and_the_rows(capsys):
    doc, cols, _ = json_doc(capsys, "dynamics", "course_slider_crank")
    code, out, err = run(capsys, "dynamics", "course_slider_crank")
    assert code == 0, err
    summary = {ln[2:].split(": ")[0]: ln[2:].split(": ", 1)[1]
               for ln in out.splitlines() if ln.startswith("# ")}
    assert summary["scheme"] == "course_slider_crank" and summary["method"] == "course"
    for key in DYNAMICS_KEYS:
        assert float(summary[key].split()[0]) == pytest.approx(doc[key], rel=1e-5), key
    # with their units
    assert summary["driving_moment"].endswith(" N m") and summary["flywheel_inertia"].endswith(" kg m^2")
    assert summary["delta_actual"].split() == [summary["delta_actual"]]  # a pure number
    table = read_table(out)
    assert list(table) == list(cols)  # every column fits in 160 characters
    for name in cols:
        scale = np.abs(cols[name]).max()
        np.testing.assert_allclose(table[name], cols[name], rtol=1e-6, atol=1e-9 * scale, err_msg=name)


def test_dynamics_overrides_on_a_scheme_without_dynamics(capsys):
    code, out, err = run(capsys, "dynamics", "four_bar")
    assert code == 2 and out == "" and "Traceback" not in err
    assert "four_bar" in err and "[dynamics]" in err
    code, out, err = run(capsys, "dynamics", "four_bar", "--omega", "10")  # no delta to size with
    assert code == 2 and out == "" and "delta" in err
    doc, cols, _ = json_doc(capsys, "dynamics", "four_bar", "--omega", "10", "--delta", "0.05",
                            "--positions", "8")
    assert len(doc["rows"]) == 9
    np.testing.assert_allclose(np.diff(cols["phi_deg"]), 45.0, atol=1e-9)  # CCW: omega > 0
    assert np.all(cols["omega"] > 0)
    assert doc["delta_actual"] == pytest.approx(0.05, rel=1e-12)
    # gravity alone is conservative: the cycle needs (almost) no driving moment
    assert abs(doc["driving_moment"]) < 1e-3 * np.abs(cols["reduced_moment_resistance"]).max()
    w = np.abs(cols["omega"])
    assert (w.max() + w.min()) / 2 == pytest.approx(10.0, rel=1e-2)


def test_dynamics_omega_and_delta_override_the_scheme(capsys):
    doc, cols, _ = json_doc(capsys, "dynamics", "course_slider_crank", "--omega", "-5",
                            "--delta", "0.1")
    close(cols["reduced_moment_resistance"], reduced_resistance(np.radians(PHI0_DEG - cols["phi_deg"])))
    ref = mertsalov(cols["reduced_moment_resistance"], 0.1, mean_speed=-5.0)
    assert ref["flywheel"] > 0
    assert doc["driving_moment"] == pytest.approx(ref["driving"], rel=1e-9)
    assert doc["required_constant_inertia"] == pytest.approx(ref["required"], rel=1e-9)
    assert doc["flywheel_inertia"] == pytest.approx(ref["flywheel"], rel=1e-9)
    assert doc["delta_actual"] == pytest.approx(0.1, rel=1e-12)
    close(cols["omega"], ref["omega"])
    close(cols["eps"], ref["eps"], rel=1e-8)


def test_dynamics_rpm_overrides_the_sense_of_rotation(capsys):
    """--rpm overrides the declared mean speed, sign included: positions then go CCW."""
    doc, cols, _ = json_doc(capsys, "dynamics", "course_slider_crank", "--rpm", "50")
    assert np.all(cols["omega"] > 0)
    np.testing.assert_allclose(cols["phi_deg"], 30.0 * np.arange(13), atol=1e-9)
    w = np.abs(cols["omega"])
    wm = 50 * 2 * math.pi / 60
    assert (w.max() + w.min()) / 2 == pytest.approx(wm, rel=1e-2)


# ----------------------------------------------------------------------------------------------
# linkage dynamics: the exact and ode methods on the flying shears
# ----------------------------------------------------------------------------------------------


def test_dynamics_exact_method_on_flying_shears(capsys):
    doc, cols, err = json_doc(capsys, "dynamics", "flying_shears", "--method", "exact")
    assert doc["method"] == "exact"
    for key in DYNAMICS_KEYS:
        assert key in doc, key
    assert doc["delta_actual"] == pytest.approx(0.08, abs=1e-9)
    assert doc["flywheel_inertia"] is not None and doc["flywheel_inertia"] > 0
    assert len(doc["rows"]) == 73  # the scheme's 72 positions
    w, wm = np.abs(cols["omega"]), 2 * math.pi  # mean_rpm = 60
    assert np.all(cols["omega"] > 0)
    assert cols["omega"][-1] == pytest.approx(cols["omega"][0], rel=1e-9)  # steady: periodic
    assert (w.max() - w.min()) / wm == pytest.approx(0.08, abs=5e-3)  # 5 deg rows vs a fine grid
    assert (w.max() + w.min()) / 2 == pytest.approx(wm, rel=2e-3)
    assert doc["dynamic_coefficient"] == pytest.approx(
        np.abs(cols["balancing_moment"]).max() / abs(doc["driving_moment"]), rel=1e-12)
    # the same solution on 0.5 deg rows (--positions 720): the energy equation
    # I w^2 / 2 - I_1 w_1^2 / 2 = M_d psi + A_c(psi), with A_c by the trapezoid on the rows
    fine_doc, fine, _ = json_doc(capsys, "dynamics", "flying_shears", "--method", "exact",
                                 "--positions", "720")
    assert len(fine_doc["rows"]) == 721
    assert fine_doc["driving_moment"] == pytest.approx(doc["driving_moment"], rel=1e-12)
    step = 2 * math.pi / 720
    work_c = trapezoid_cumulative(fine["reduced_moment_resistance"], step)
    assert fine_doc["driving_moment"] == pytest.approx(-work_c[-1] / (2 * math.pi), rel=2e-3)
    w = np.abs(fine["omega"])
    # the machine's reduced inertia (I_0 + I'') plus the flywheel the method adds
    energy = (fine["reduced_inertia"] + fine_doc["flywheel_inertia"]) * w**2 / 2
    work = fine_doc["driving_moment"] * step * np.arange(721) + work_c
    np.testing.assert_allclose(energy - energy[0], work, atol=2e-3 * (energy.max() - energy.min()))
    assert (w.max() - w.min()) / wm == pytest.approx(0.08, abs=3e-4)
    assert (w.max() + w.min()) / 2 == pytest.approx(wm, rel=1e-4)


def test_dynamics_ode_method_on_flying_shears(capsys):
    doc, cols, err = json_doc(capsys, "dynamics", "flying_shears", "--method", "ode")
    assert doc["method"] == "ode" and "linkage: note:" in err
    for key in DYNAMICS_KEYS + ("settling_time",):
        assert key in doc, key
    assert doc["settling_time"] is not None and 0 < doc["settling_time"] < doc["transient_time"]
    w = np.abs(cols["omega"])
    assert np.all(cols["omega"] > 0)
    assert cols["omega"][-1] == pytest.approx(cols["omega"][0], rel=1e-6)  # periodic steady state
    # the motor's steady speed: between the load's 60 rpm design point and the synchronous
    # 1500 / 23.5 rpm of the induction motor
    assert 2 * math.pi < (w.max() + w.min()) / 2 < 1500 / 23.5 * 2 * math.pi / 60
    assert (w.max() - w.min()) / ((w.max() + w.min()) / 2) == pytest.approx(doc["delta_actual"], abs=5e-3)
    assert doc["dynamic_coefficient"] == pytest.approx(
        np.abs(cols["balancing_moment"]).max() / abs(doc["driving_moment"]), rel=1e-12)


def test_dynamics_bad_method_exits_2(capsys):
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--method", "magic")
    assert code == 2 and out == ""


def test_dynamics_refuses_a_delta_of_two_or_more(capsys):
    code, out, err = run(capsys, "dynamics", "course_slider_crank", "--delta", "5")
    assert code == 2 and "delta" in err and "(0, 2)" in err and "Traceback" not in err
