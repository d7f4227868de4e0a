"""Answer keys for grading step by step (linkage/course/key.py, docs/templates.md "[template.grading]").

Oracles are independent of the library: the offset slider-crank's positions, analogs, velocities
and accelerations in closed form (METHOD 8) for a clockwise and a counter-clockwise crank; the
graphical differentiation of the key's own positions over psi; Mertsalov's chain (A_c, A_d, Delta T,
T'', Delta T', I', I_fw, omega, eps) recomputed here from the key's own per-position values; the
key's CSV read back with the csv module.
"""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest

import linkage
from linkage.course.key import KEY_COLUMNS, AnswerKey, answer_key
from linkage.course.template import Grading, loads_template
from linkage.dynamics.pipeline import run_dynamics
from linkage.errors import InputError, SchemeError
from linkage.model.scheme import loads

L1, L2, E, AS = 0.1, 0.35, 0.02, 0.12   # crank OA, rod AB, guide offset e, AS2 (m)
W = 10.0                                 # |mean speed|, rad/s
N = 36                                   # table positions (10 deg apart)

#: an offset slider-crank with a resistance on the slider's working stroke; {speed} signed
SLIDER_CRANK = f'''
name = "slider_crank_key"
input = "1"
output = {{ quantity = "B.x", start = "max" }}
[links.0]
points = {{ O = [0.0, 0.0] }}
guides.slide = {{ through = [0.0, {E}], angle_deg = 0 }}
[links.1]
line = ["O", "A"]
length = {L1}
mass = 5.0
com = "O"
[links.2]
line = ["A", "B"]
length = {L2}
points.S2 = {{ from = "A", distance = {AS} }}
mass = 20.0
com = "S2"
inertia = 0.2
[links.3]
points.B = [0.0, 0.0]
mass = 30.0
com = "B"
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
[assembly.B]
from = "O"
towards_deg = 0
[loads]
gravity = [0.0, -9.81]
[[loads.forces]]
point = "B"
link = "3"
diagram = {{ along = "x", working = "+", fractions = [0, 0.5, 1], values = [0, 1500, 1500] }}
[dynamics]
mean_speed = {{speed}}
delta = 0.05
positions = {N}
inertia_0 = 0.5
'''

SENSES = pytest.mark.parametrize("sense", [1, -1], ids=["ccw", "cw"])


def mechanism(sense: int):
    return loads(SLIDER_CRANK.replace("{speed}", repr(sense * W)), source=f"sense {sense}")


@pytest.fixture(scope="module")
def keys() -> dict[int, AnswerKey]:
    return {sense: answer_key(mechanism(sense)) for sense in (1, -1)}


def series(key: AnswerKey, quantity: str) -> np.ndarray:
    """The key's values of ``quantity`` in position order."""
    values = key.series(quantity)
    assert list(values) == sorted(values)
    return np.array(list(values.values()))


def close(actual, expected, scale, rel=1e-9):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rel * scale)


# ----------------------------------------------------------------------------------------------
# the closed-form slider-crank, both senses of rotation
# ----------------------------------------------------------------------------------------------


def closed_form(phi: np.ndarray) -> dict[str, np.ndarray]:
    """x_B, theta_2 and S2 with their first and second analogs d/dphi (METHOD 8, written out)."""
    sin_t = (E - L1 * np.sin(phi)) / L2          # y_B = l1 sin(phi) + l2 sin(theta) = e
    cos_t = np.sqrt(1 - sin_t**2)                 # B right of A
    t1 = -L1 * np.cos(phi) / (L2 * cos_t)         # i21
    t2 = (L1 * np.sin(phi) + L2 * sin_t * t1**2) / (L2 * cos_t)
    return {
        "B.x": L1 * np.cos(phi) + L2 * cos_t,
        "B.x'": -L1 * np.sin(phi) - L2 * sin_t * t1,
        "B.x''": -L1 * np.cos(phi) - L2 * cos_t * t1**2 - L2 * sin_t * t2,
        "theta": np.arctan2(sin_t, cos_t), "theta'": t1, "theta''": t2,
        "S2.x'": -L1 * np.sin(phi) - AS * sin_t * t1, "S2.y'": L1 * np.cos(phi) + AS * cos_t * t1,
        "S2.x''": -L1 * np.cos(phi) - AS * (cos_t * t1**2 + sin_t * t2),
        "S2.y''": -L1 * np.sin(phi) + AS * (cos_t * t2 - sin_t * t1**2),
    }


@SENSES
def test_positions_start_at_the_far_dead_centre_and_turn_in_the_sense_of_rotation(keys, sense):
    key = keys[sense]
    phi0 = math.asin(E / (L1 + L2))               # A and B in line: (l1 + l2) sin(phi0) = e
    expected = np.degrees(phi0 + sense * np.arange(N + 1) * 2 * np.pi / N)
    turned = (np.asarray(key.meta["input_angle_deg"]) - expected + 180) % 360 - 180
    close(turned, np.zeros(N + 1), 1.0, 1e-9)
    close(key.meta["psi_deg"], np.arange(N + 1) * 360 / N, 360, 1e-12)
    assert key.meta["direction"] == sense and key.meta["mean_speed"] == sense * W


@SENSES
def test_slider_and_rod_match_the_closed_form_in_si_units(keys, sense):
    key = keys[sense]
    phi = np.radians(key.meta["input_angle_deg"][:N])   # kinematics: positions 1 .. n
    ref = closed_form(phi)
    w = sense * W
    assert sorted(key.series("B.x")) == list(range(1, N + 1))
    close(series(key, "B.x"), ref["B.x"], L1)
    close(series(key, "B.vx"), ref["B.x'"] * w, L1 * W)                  # m/s
    close(series(key, "B.v"), np.abs(ref["B.x'"] * w), L1 * W)
    close(series(key, "B.ax"), ref["B.x''"] * w**2, L1 * W**2)            # m/s^2 (eps of the crank 0)
    close(series(key, "2.theta_deg"), np.degrees(ref["theta"]), 180)
    close(series(key, "2.omega"), ref["theta'"] * w, W)                    # rad/s
    close(series(key, "2.eps"), ref["theta''"] * w**2, W**2)               # rad/s^2
    close(series(key, "S2.vx"), ref["S2.x'"] * w, L1 * W)
    close(series(key, "S2.vy"), ref["S2.y'"] * w, L1 * W)
    close(series(key, "S2.ay"), ref["S2.y''"] * w**2, L1 * W**2)
    close(series(key, "S2.a"), np.hypot(ref["S2.x''"], ref["S2.y''"]) * w**2, L1 * W**2)
    # analogs for people: d/dpsi, psi the angle turned (dq/dpsi = sense dq/dphi; d2q/dpsi2 = d2q/dphi2)
    close(series(key, "B.x'"), sense * ref["B.x'"], L1)
    close(series(key, "B.x''"), ref["B.x''"], L1)
    close(series(key, "2.theta'"), sense * ref["theta'"], 1)
    close(series(key, "2.theta''"), ref["theta''"], 1)
    assert key.item("B.vx", 2).unit == "m/s" and key.item("B.ax", 2).unit == "m/s^2"
    assert key.item("2.omega", 2).unit == "rad/s" and key.item("2.eps", 2).unit == "rad/s^2"
    assert key.item("B.x'", 2).unit == "m/rad" and key.item("2.theta_deg", 2).unit == "deg"


@SENSES
def test_the_other_assembly_mode_is_the_slider_on_the_other_side(keys, sense):
    """A student who assembles the slider left of the crank's pivot: the key's ``other_mode``."""
    key = keys[sense]
    phi = np.radians(key.meta["input_angle_deg"][:N])
    ref = closed_form(phi)
    sin_t = (E - L1 * np.sin(phi)) / L2
    cos_t = -np.sqrt(1 - sin_t**2)                # B left of A
    t1 = -L1 * np.cos(phi) / (L2 * cos_t)
    x = L1 * np.cos(phi) + L2 * cos_t
    x1 = -L1 * np.sin(phi) - L2 * sin_t * t1
    other = {q: np.array([key.item(q, i).other_mode for i in range(1, N + 1)]) for q in ("B.x", "B.vx", "2.omega")}
    close(other["B.x"], x, L1)
    close(other["B.vx"], x1 * sense * W, L1 * W)
    close(other["2.omega"], t1 * sense * W, W)
    assert not np.allclose(other["B.x"], ref["B.x"])
    assert key.item("driving_moment").other_mode is None      # only the kinematics has one


@SENSES
def test_analogs_are_the_central_differences_of_the_positions_over_psi(keys, sense):
    """Graphical differentiation: over psi (the position axis) a curve's slope is its analog,
    whatever the sense of rotation. The central difference over 10 deg is exact to about 1 %."""
    key = keys[sense]
    h = 2 * np.pi / N

    def slope(values):   # periodic: position n+1 is position 1
        return (np.roll(values, -1) - np.roll(values, 1)) / (2 * h)

    for value, first, second in (("B.x", "B.x'", "B.x''"), ("S2.y", "S2.y'", "S2.y''")):
        d1, d2 = series(key, first), series(key, second)
        close(slope(series(key, value)), d1, np.abs(d1).max(), 0.015)
        close(slope(d1), d2, np.abs(d2).max(), 0.015)
    theta = np.unwrap(np.radians(series(key, "2.theta_deg")))
    close(slope(theta), series(key, "2.theta'"), np.abs(series(key, "2.theta'")).max(), 0.015)
    # the slider moves back from the far dead centre: x falls and its analog is negative at first
    assert series(key, "B.x")[1] < series(key, "B.x")[0] and series(key, "B.x'")[1] < 0


# ----------------------------------------------------------------------------------------------
# Mertsalov's chain from the key's own values
# ----------------------------------------------------------------------------------------------


def trapezoid_cumulative(values: np.ndarray, step: float) -> np.ndarray:
    out = [0.0]
    for a, b in zip(values[:-1], values[1:]):
        out.append(out[-1] + (a + b) / 2 * step)
    return np.array(out)


@pytest.mark.parametrize("which", ["ccw", "cw", "course_slider_crank"])
def test_mertsalov_chain_recomputed_from_the_keys_own_values(keys, which):
    key = {"ccw": keys.get(1), "cw": keys.get(-1)}.get(which) or answer_key(linkage.load(which))
    doc = json.loads(key.to_json())
    n = doc["positions"]
    wm, delta = doc["mean_speed"], doc["delta"]
    s = 1 if wm > 0 else -1
    psi = np.arange(n + 1) * 2 * np.pi / n
    energy = key.item("delta_T", 1).floor
    assert sorted(key.series("delta_T")) == list(range(1, n + 2))

    m_c = series(key, "reduced_moment_resistance")
    a_c = trapezoid_cumulative(m_c, 2 * np.pi / n)
    close(series(key, "work_resistance"), a_c, energy)
    m_d = -a_c[-1] / (2 * np.pi)                                      # the cycle balance
    close(key.value("driving_moment"), m_d, abs(m_d))
    close(series(key, "reduced_moment_driving"), np.full(n + 1, m_d), abs(m_d))   # M_d, not 0
    assert abs(m_d) > 1.0
    a_d = m_d * psi
    close(series(key, "work_driving"), a_d, energy)
    delta_t = a_d + a_c
    close(series(key, "delta_T"), delta_t, energy)
    assert abs(delta_t[-1]) < 1e-9 * energy                           # the cycle closes
    i_0 = key.value("reduced_inertia_constant")
    i_var = series(key, "reduced_inertia") - i_0                      # I = I_0 + I''
    close(series(key, "reduced_inertia_variable"), i_var, i_var.max())
    t_var = i_var * wm**2 / 2
    close(series(key, "T_variable"), t_var, energy)
    prime = delta_t - t_var
    close(series(key, "delta_T_prime"), prime, energy)
    close(key.value("delta_T_prime_max"), prime.max(), energy)
    close(key.value("delta_T_prime_min"), prime.min(), energy)
    swing = prime.max() - prime.min()
    close(key.value("delta_T_prime_swing"), swing, energy)
    required = swing / (delta * wm**2)
    close(key.value("required_constant_inertia"), required, required)
    close(key.value("flywheel_inertia"), required - i_0, required)
    # the law of motion by the course formulas
    constant = max(required, i_0)
    mean = (prime.max() + prime.min()) / 2
    w = np.sqrt(2 * (constant * wm**2 / 2 + prime - mean) / constant)
    close(series(key, "omega"), s * w, abs(wm))
    moment = m_c + m_d
    eps = s * (moment - 0.5 * series(key, "reduced_inertia_derivative") * w**2) / (constant + i_var)
    close(series(key, "eps"), eps, np.abs(eps).max())
    # the key's scalars as the JSON's own scalar results (the index reads them)
    assert doc["driving_moment"] == key.value("driving_moment")
    assert doc["required_constant_inertia"] == key.value("required_constant_inertia")


def test_the_dynamics_table_holds_the_driving_moment():
    mech = linkage.load("course_slider_crank")
    report = run_dynamics(mech, "course", compare=False)
    columns = report.columns()
    assert np.all(columns["reduced_moment_driving"] == report.law.driving_moment)
    assert report.law.driving_moment > 100      # 183.5 N m: the press needs a drive
    work = trapezoid_cumulative(columns["reduced_moment_resistance"] + columns["reduced_moment_driving"],
                                2 * np.pi / 12)
    assert abs(work[-1]) < 1e-9 * np.abs(work).max()   # the two columns balance over the cycle
    ode = run_dynamics(mech, "ode", compare=False)      # no motor declared: a constant moment balances it
    np.testing.assert_allclose(ode.columns()["reduced_moment_driving"], ode.law.driving_moment, rtol=1e-12)


def test_the_key_says_what_the_tables_of_the_variant_say():
    """The key's numbers are the rows of kinematics.csv, forces.csv and dynamics.csv (i = position)."""
    from linkage.report.results import dynamics_results, forces_results, kinematics_results

    mech = mechanism(-1)
    key = answer_key(mech)
    # balancing_moment: forces.csv's, at the mean speed (dynamics.csv's is under the law of motion)
    tables = {**dynamics_results(mech).columns, **kinematics_results(mech).columns, **forces_results(mech).columns}
    compared = 0
    for quantity in key.quantities:
        if quantity in tables:
            for position, value in key.series(quantity).items():
                assert value == pytest.approx(tables[quantity][position - 1], rel=1e-12,
                                              abs=1e-12 * key.item(quantity, position).floor), (quantity, position)
                compared += 1
    assert compared > 500


# ----------------------------------------------------------------------------------------------
# kinetostatics: the lever and the kinetostatics agree
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("which", ["ccw", "cw", "course_slider_crank"])
def test_lever_balancing_moment_equals_the_kinetostatic_one(keys, which):
    key = {"ccw": keys.get(1), "cw": keys.get(-1)}.get(which) or answer_key(linkage.load(which))
    by_forces, by_lever = series(key, "balancing_moment"), series(key, "lever_balancing_moment")
    assert len(by_forces) == key.meta["positions"] + 1
    close(by_lever, by_forces, np.abs(by_forces).max(), 1e-6)
    assert key.item("balancing_moment", 1).unit == "N m" and key.item("A.R", 1).unit == "N"
    assert {"O.R", "A.R", "B.R", "slide.R", "O.angle_deg"} <= set(key.quantities)


# ----------------------------------------------------------------------------------------------
# the files
# ----------------------------------------------------------------------------------------------


def test_key_csv_has_exactly_the_columns_and_one_row_per_quantity_and_position(keys):
    key = keys[-1]
    text = key.to_csv()
    rows = list(csv.reader(io.StringIO(text)))
    assert tuple(rows[0]) == KEY_COLUMNS == ("quantity", "position", "value", "unit", "tolerance")
    body = rows[1:]
    assert len(body) == len(key.items)
    pairs = [(r[0], r[1]) for r in body]
    assert len(set(pairs)) == len(pairs)
    for row, item in zip(body, key.items):
        assert row[0] == item.quantity and row[3] == item.unit
        assert row[1] == ("" if item.position is None else str(item.position))
        assert float(row[2]) == item.value and float(row[4]) == item.tolerance == 0.02
    scalars = {r[0] for r in body if r[1] == ""}
    assert {"driving_moment", "required_constant_inertia", "flywheel_inertia", "stroke"} <= scalars
    doc = json.loads(key.to_json())
    assert {"variant", "template", "parameters", "checks", "conventions", "digits", "items", "notes"} <= set(doc)
    fields = {"quantity", "position", "value", "unit", "tolerance", "digits", "floor"}
    assert all(fields <= i.keys() <= fields | {"other_mode"} for i in doc["items"])
    assert all(i["digits"] == 4 for i in doc["items"])
    # the floor: the largest magnitude over the positions (a vector's for its components)
    floor = key.item("B.vx", 3).floor
    assert floor == pytest.approx(max(abs(v) for v in key.series("B.v").values()), rel=1e-15)
    assert key.item("B.x", 1).floor >= max(abs(v) for v in key.series("B.x").values())


def test_a_variants_key_carries_its_labels_and_every_field_of_the_dynamics_json():
    mech = mechanism(-1)
    key = answer_key(mech, variant="7", template="press", parameters={"r": 0.1}, checks={"stroke": 0.2})
    doc = json.loads(key.to_json())
    assert (doc["variant"], doc["template"], doc["parameters"], doc["checks"]) == ("7", "press", {"r": 0.1},
                                                                                  {"stroke": 0.2})
    from linkage.report.results import dynamics_results
    direct = json.loads(dynamics_results(mech).json())
    for field, value in direct.items():
        assert doc[field] == value, field


# ----------------------------------------------------------------------------------------------
# [template.grading]
# ----------------------------------------------------------------------------------------------

#: the slider-crank as a template: the crank's length a parameter
TEMPLATE = (SLIDER_CRANK.replace("{speed}", "-10.0").replace(f"length = {L1}", 'length = "= r"')
            + '\n[template.parameters]\nr = { values = [0.09, 0.1] }\n')


def test_tolerances_digits_points_and_positions_from_the_grading_section_reach_the_rows():
    t = loads_template(TEMPLATE + '''
[template.grading]
tolerance = 0.03
digits = 3
points = ["B"]
force_positions = [1, 10, 37]
tolerances = { "B.v" = 0.01, "*.R" = 0.05, "B.*" = 0.04 }
''')
    assert t.grading == Grading(0.03, 3, ("B",), (1, 10, 37), {"B.v": 0.01, "*.R": 0.05, "B.*": 0.04})
    key = answer_key(t.mechanism({"r": 0.1}), template=t, variant="1", parameters=t.values({"r": 0.1}))
    tolerance = {row["quantity"]: float(row["tolerance"]) for row in csv.DictReader(io.StringIO(key.to_csv()))}
    assert tolerance["B.v"] == 0.01                          # its own name
    assert tolerance["A.R"] == tolerance["B.R"] == 0.05      # the first pattern that matches
    assert tolerance["B.x"] == tolerance["B.ax"] == 0.04
    assert tolerance["2.omega"] == tolerance["delta_T"] == 0.03
    assert all(it.digits == 3 for it in key.items) and json.loads(key.to_json())["digits"] == 3
    assert not any(q.startswith("S2.") for q in key.quantities)    # only B asked
    assert sorted(key.series("A.R")) == [1, 10, 37] and sorted(key.series("balancing_moment")) == [1, 10, 37]
    assert key.meta["template"] == t.name


def test_default_points_are_the_output_and_the_named_centres_of_mass(keys):
    quantities = keys[1].quantities
    assert {"B.x", "S2.x", "S2.vy"} <= set(quantities)
    assert not any(q.startswith(("O.x", "O.v", "A.x", "A.v")) for q in quantities)   # the frame's pivot; A not asked
    assert "O.R" in quantities                                       # (the pair O's reaction is)
    assert "1.omega" not in quantities                               # the crank's motion is given
    assert "3.omega" not in quantities                               # the slider does not turn
    assert "B.vy" not in quantities                                  # 0 at every position


@pytest.mark.parametrize("grading, says", [
    ("tolerance = 2", "[template.grading] tolerance: expected a relative tolerance, a number in (0, 1]"),
    ("tolerance = \"2 %\"", "[template.grading] tolerance: expected a relative tolerance"),
    ("digits = 0", "[template.grading] digits: expected a whole number of significant digits, 1 .. 15, got 0"),
    ("digits = 3.5", "[template.grading] digits: expected a whole number of significant digits, 1 .. 15, got 3.5"),
    ('points = ["B", "Q"]', "[template.grading] points: 'Q' is not a point of the scheme"),
    ('points = "B"', "[template.grading] points: expected a list of point names, got 'B'"),
    ("force_positions = [1, 38]", "[template.grading] force_positions: 38 is not a table position (1 .. 37"),
    ("force_positions = [0]", "[template.grading] force_positions: 0 is not a table position"),
    ("force_positions = [1, 1]", "[template.grading] force_positions: 1 listed more than once"),
    ('tolerances = { "B.vv" = 0.01 }', "[template.grading] tolerances: 'B.vv' is not a quantity of the key; "
                                       "did you mean 'B.v'?"),
    ('tolerances = { "*.Q" = 0.01 }', "[template.grading] tolerances: the pattern '*.Q' matches no quantity"),
    ('tolerances = { "B.v" = 0 }', "[template.grading] tolerances 'B.v': expected a relative tolerance"),
    ("tolerances = 0.1", "[template.grading] tolerances: expected a table"),
    ("toleranse = 0.1", "[template.grading]: unknown keys ['toleranse']"),
])
def test_grading_section_errors_name_the_key_and_the_value(grading, says):
    with pytest.raises(SchemeError) as err:
        loads_template(TEMPLATE + "\n[template.grading]\n" + grading + "\n", source="t.toml")
    assert str(err.value).startswith("t.toml: ") and says in str(err.value), str(err.value)


def test_a_grading_the_mechanism_does_not_fit_is_refused_when_the_key_is_made():
    mech = mechanism(1)
    with pytest.raises(InputError, match=r"points: \['Q'\] are not points of mechanism"):
        answer_key(mech, Grading(points=("Q",)))
    with pytest.raises(InputError, match=r"force_positions: \[40\] are not table positions \(1 \.\. 37\)"):
        answer_key(mech, Grading(force_positions=(1, 40)))


# ----------------------------------------------------------------------------------------------
# what applies
# ----------------------------------------------------------------------------------------------


def test_without_dynamics_the_key_holds_positions_analogs_and_static_reactions():
    key = answer_key(linkage.load("slider_crank"))        # no [dynamics] section
    quantities = set(key.quantities)
    assert {"B.x", "B.x'", "B.x''", "balancing_moment", "lever_balancing_moment", "A.R"} <= quantities
    assert not quantities & {"B.vx", "B.v", "2.omega", "delta_T", "omega", "driving_moment"}
    notes = " ".join(key.notes)
    assert "no [dynamics] mean speed" in notes and "static" in notes and "no dynamics" in notes
    close(series(key, "lever_balancing_moment"), series(key, "balancing_moment"),
          np.abs(series(key, "balancing_moment")).max(), 1e-6)


def test_without_masses_or_loads_the_key_leaves_out_the_reactions():
    text = "\n".join(line for line in SLIDER_CRANK.replace("{speed}", "10.0").splitlines()
                     if not line.startswith(("mass", "inertia =", "com")))
    text = text[:text.index("[loads]")] + text[text.index("[dynamics]"):].replace("delta = 0.05\n", "")
    key = answer_key(loads(text))
    assert "B.vx" in key.quantities and "A.R" not in key.quantities and "balancing_moment" not in key.quantities
    assert any("no masses and no loads" in note for note in key.notes)
