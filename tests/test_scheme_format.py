"""The scheme format of issue 8 (Build item 7, "What was seen" 3 and 7).

- step diagrams: a fraction given twice is a jump, with the value just before and just after it;
- directed forces: along the line through two points (``between``) or fixed in a link
  (``along_link``, ``angle_deg``), with a constant signed ``magnitude``, a signed diagram or a
  cycle table, in the loads, the kinetostatics, the reduced moments and the dynamics;
- an input range (``range_deg``, ``--range A B``) for mechanisms whose input does not turn fully;
- a start from rest (``initial_speed = 0`` / ``initial_rpm = 0``) with any motor that has a
  starting torque;
- refusals of what cannot be meant (a cycle table of the wrong length, an assembly condition no
  branch meets), each naming the file, the entry and the value;
- every TOML example of ``schemes/README.md`` loads.

Every expected number is computed here from closed forms: the press's x_B(phi) and its stroke ends
(collinear crank and rod), the tangent mechanism's x_B = h cot(phi) and |OB| = h / sin(phi), the
rocker slider-crank x_B = l1 cos(phi) + sqrt(l2^2 - l1^2 sin^2(phi)), Kloss's moment at slip 1, and
the start-up of a constant inertia under a linear motor, omega(t) = w0 (1 - exp(-M0 t / (I w0))).
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import linkage
from linkage import InputError, SchemeError
from linkage.dynamics import course_method, dynamics_of, exact_method, run_dynamics, simulate, steady_state
from linkage.errors import DynamicsError, DynamicsInputError
from linkage.kinetostatics.loads import diagram_value, evaluate_loads, loads_of
from linkage.kinetostatics.reactions import solve_reactions
from linkage.dynamics.motors import LinearMotor, starting_moment
from linkage.dynamics.reduced import reduced_characteristics
from linkage.model.scheme import from_dict, to_dict

from _cli_io import read_csv, run
from _texts import slider_crank_toml

README = Path(__file__).resolve().parent.parent / "schemes" / "README.md"

# ----------------------------------------------------------------------------------------------
# the press (shipped slider_crank): closed forms
# ----------------------------------------------------------------------------------------------

L1, L2, E = 0.0742, 0.2225, 0.01335
X_MAX = math.sqrt((L1 + L2) ** 2 - E**2)  # crank and rod extended
X_MIN = math.sqrt((L2 - L1) ** 2 - E**2)  # folded
STROKE = X_MAX - X_MIN
PHI_MAX = math.atan2(E, X_MAX)
PHI_MIN = math.atan2(E, X_MIN) + math.pi


def x_b(phi):
    phi = np.asarray(phi, float)
    return L1 * np.cos(phi) + np.sqrt(L2**2 - (L1 * np.sin(phi) - E) ** 2)


def phi_at_fraction(t):
    """Input angle on the press's working stroke (x_B increasing, omega > 0) at stroke fraction t."""
    target = X_MIN + t * STROKE
    return brentq(lambda p: x_b(p) - target, PHI_MIN, PHI_MAX + 2 * np.pi, xtol=1e-15, rtol=1e-15)


def press(loads, dynamics=None, massless=False):
    data = to_dict(linkage.load("slider_crank"))
    data["loads"] = loads
    if dynamics is not None:
        data["dynamics"] = dynamics
    if massless:
        for k in ("1", "2", "3"):
            data["links"][k].pop("mass", None)
            data["links"][k]["inertia"] = 0.0
    return from_dict(data)


def external(mech, phi, omega, ends=None):
    """The (only) external force term evaluated by the library at ``phi``."""
    motion = linkage.analyze(mech, phi, omega=omega)
    (term,) = [t for t in evaluate_loads(motion, loads_of(mech), ends) if t.kind != "gravity"]
    return term


# ----------------------------------------------------------------------------------------------
# 1. step diagrams
# ----------------------------------------------------------------------------------------------

STEPS = dict(fractions=[0, 0.3, 0.3, 0.6, 0.6, 1], values=[0, 300, 2100, 1500, 200, 0])


def step_by_hand(t, before=False):
    """The diagram STEPS read by hand: 1000 t up to 0.3, then 2100 - 2000 (t - 0.3) up to 0.6,
    then 500 (1 - t); at a jump the value after it, or before it when ``before``."""
    if t < 0.3 or (t == 0.3 and before):
        return 1000 * t
    if t < 0.6 or (t == 0.6 and before):
        return 2100 - 2000 * (t - 0.3)
    return 500 * (1 - t)


def test_diagram_value_keeps_both_values_at_a_jump():
    ts = [0.0, 0.15, 0.3, 0.45, 0.6, 0.8, 1.0]
    got = diagram_value(ts, STEPS["fractions"], STEPS["values"])
    np.testing.assert_allclose(got, [step_by_hand(t) for t in ts], rtol=0, atol=1e-12)
    got = diagram_value(ts, STEPS["fractions"], STEPS["values"], before=True)
    np.testing.assert_allclose(got, [step_by_hand(t, before=True) for t in ts], rtol=0, atol=1e-12)
    # round-off of a position placed at the jump does not move it off the jump
    assert diagram_value([0.3 + 1e-15, 0.3 - 1e-15], STEPS["fractions"], STEPS["values"]).tolist() == [2100, 2100]


def test_step_diagram_on_the_press():
    """Positions at stroke fractions computed from the closed-form x_B; the force opposes the
    slider's motion towards +x with the diagram's magnitude, both values kept at the jumps."""
    mech = press({"gravity": [0, 0], "forces": [
        {"point": "B", "link": "3", "diagram": {"along": "x", "working": "+", **STEPS}}]})
    ts = [0.1, 0.3 - 1e-6, 0.3, 0.3 + 1e-6, 0.45, 0.6 - 1e-6, 0.6, 0.6 + 1e-6, 0.9]
    phi = np.array([phi_at_fraction(t) for t in ts])
    term = external(mech, phi, 10.0)
    np.testing.assert_allclose(term.force[:, 0], [-step_by_hand(t) for t in ts], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(term.force[:, 1], 0.0)
    # a position that ends the cycle (``ends``) at the jump carries the value the motion arrives with
    at_jumps = phi[[2, 6]]
    arriving = external(mech, at_jumps, 10.0, ends=[True, True]).force[:, 0]
    np.testing.assert_allclose(arriving, [-300.0, -1500.0], rtol=0, atol=1e-6)


def test_step_diagram_work_over_the_cycle():
    """The cycle's driving moment balances the work of the step diagram: stroke x area / (2 pi),
    area = 0.3 x 300 / 2 + 0.3 x (2100 + 1500) / 2 + 0.4 x 200 / 2 = 625 N."""
    mech = press({"gravity": [0, 0], "forces": [
        {"point": "B", "link": "3", "diagram": {"along": "x", "working": "+", **STEPS}}]},
        {"mean_speed": 10.0, "delta": 0.05, "inertia_0": 5.0})
    law = exact_method(mech)
    assert law.driving_moment == pytest.approx(STROKE * 625 / (2 * np.pi), rel=2e-3)


@pytest.mark.parametrize("fractions, needle", [
    ([0, 0, 0.5, 1], "stroke end 0"),
    ([0, 0.4, 0.4, 0.4, 1], "three times"),
    ([0, 0.6, 0.5, 1], "increase from 0 to 1"),
])
def test_fractions_that_cannot_be_meant_are_refused(tmp_path, fractions, needle):
    text = linkage.dumps(linkage.load("slider_crank")) + (
        '\n[[loads.forces]]\npoint = "B"\nlink = "3"\n'
        f'diagram = {{ along = "x", working = "+", fractions = {fractions}, values = {[1] * len(fractions)} }}\n')
    path = tmp_path / "steps.toml"
    path.write_text(text)
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    (problem,) = info.value.problems
    for part in ("steps.toml", "forces[0]", "fractions", needle, str(fractions)):
        assert part in problem, (part, problem)


# ----------------------------------------------------------------------------------------------
# 2. directed forces, on the tangent mechanism: x_B = h cot(phi), B on the slot at |OB| = h / sin(phi)
# ----------------------------------------------------------------------------------------------

H = 0.1
TANGENT = f"""
name = "tangent"
input = "1"
output = {{ quantity = "B.x", start = "max" }}
range_deg = [30, 150]

[links.0]
points = {{ O = [0.0, 0.0] }}
guides.rail = {{ through = [0.0, {H}], angle_deg = 0 }}

[links.1]                                   # the slotted crank; the slot runs along its x axis
points = {{ O = [0.0, 0.0] }}
guides.slot = {{ through = "O", angle_deg = 0 }}

[links.2]                                   # block in the slot
points = {{ B = [0.0, 0.0] }}

[links.3]                                   # slider on the rail y = h
points = {{ B = [0.0, 0.0] }}

[pairs.O]
links = ["0", "1"]
[pairs.slot]
kind = "P"
links = ["1", "2"]
guide = "slot"
at = "B"
[pairs.B]
links = ["2", "3"]
[pairs.rail]
kind = "P"
links = ["0", "3"]
guide = "rail"
at = "B"
"""
PHI_T = np.radians(np.linspace(33.0, 147.0, 20))


def tangent(extra: str = "", **replace_text):
    text = TANGENT
    for old, new in replace_text.items():
        text = text.replace(old, new)
    return linkage.loads(text + extra, source="tangent.toml")


def force_entry(**keys):
    lines = "\n".join(f"{k} = {v}" for k, v in keys.items())
    return f'\n[loads]\ngravity = [0.0, 0.0]\n\n[[loads.forces]]\npoint = "B"\nlink = "3"\n{lines}\n'


def test_tangent_oracle():
    mech = tangent()
    motion = linkage.analyze(mech, PHI_T)
    np.testing.assert_allclose(motion.point("B")[:, 0], H / np.tan(PHI_T), rtol=0, atol=1e-15)
    np.testing.assert_allclose(motion.quantity("B.x")[1], -H / np.sin(PHI_T) ** 2, rtol=1e-13)
    np.testing.assert_allclose(motion.quantity("slot.s")[0], H / np.sin(PHI_T), rtol=1e-14)


def test_force_between_two_points():
    """F along O -> B (positive: from O towards B): F = m (cos phi, sin phi); with no inertia
    M_b = -F . r'_B = m h cos(phi) / sin^2(phi) (virtual work, r'_B = (-h / sin^2 phi, 0))."""
    m = 250.0
    mech = tangent(force_entry(between='["O", "B"]', magnitude=m))
    term = external(mech, PHI_T, 1.0)
    np.testing.assert_allclose(term.force, m * np.stack([np.cos(PHI_T), np.sin(PHI_T)], axis=1),
                               rtol=0, atol=1e-12 * m)
    r = solve_reactions(linkage.analyze(mech, PHI_T, omega=1.0, eps=0.0), inertia=False)
    np.testing.assert_allclose(r.balancing_moment, m * H * np.cos(PHI_T) / np.sin(PHI_T) ** 2,
                               rtol=1e-12, atol=1e-12 * m * H)
    # reduced moment, clockwise rotation: M_red = s F . r'_B with s = -1
    red = reduced_characteristics(mech, PHI_T, -1)
    np.testing.assert_allclose(red.moment_resistance, m * H * np.cos(PHI_T) / np.sin(PHI_T) ** 2,
                               rtol=1e-12, atol=1e-12 * m * H)
    # the sign of the direction is the order of the points
    flipped = tangent(force_entry(between='["B", "O"]', magnitude=m))
    np.testing.assert_allclose(external(flipped, PHI_T, 1.0).force, -term.force, rtol=0, atol=1e-12 * m)


def test_force_fixed_in_a_link():
    """Along the crank's direction turned by 90 deg: F = m (-sin phi, cos phi), M_b = -m h / sin(phi);
    fixed in the frame at 180 deg: F = (-m, 0), M_b = -m h / sin^2(phi)."""
    m = 40.0
    mech = tangent(force_entry(along_link='"1"', angle_deg=90, magnitude=m))
    term = external(mech, PHI_T, 1.0)
    np.testing.assert_allclose(term.force, m * np.stack([-np.sin(PHI_T), np.cos(PHI_T)], axis=1),
                               rtol=0, atol=1e-12 * m)
    r = solve_reactions(linkage.analyze(mech, PHI_T, omega=1.0, eps=0.0), inertia=False)
    np.testing.assert_allclose(r.balancing_moment, -m * H / np.sin(PHI_T), rtol=1e-12)
    fixed = tangent(force_entry(along_link='"0"', angle=math.pi, magnitude=m))
    r = solve_reactions(linkage.analyze(fixed, PHI_T, omega=1.0, eps=0.0), inertia=False)
    np.testing.assert_allclose(r.balancing_moment, -m * H / np.sin(PHI_T) ** 2, rtol=1e-12)


def test_directed_force_with_a_signed_step_diagram():
    """Working stroke: x_B decreasing (omega > 0 over [30, 150] deg); t = (x_max - x) / stroke with
    x_max = h cot 30 deg = -x_min. Signed values: +100 N before t = 0.5, -300 N after, none idle."""
    mech = tangent(force_entry(between='["O", "B"]', diagram='{ quantity = "B.x", working = "-", '
                               'fractions = [0, 0.5, 0.5, 1], values = [100, 100, -300, -300] }'))
    x_max = H / math.tan(math.radians(30))
    t = (x_max - H / np.tan(PHI_T)) / (2 * x_max)
    magnitude = np.where(t < 0.5, 100.0, -300.0)
    unit = np.stack([np.cos(PHI_T), np.sin(PHI_T)], axis=1)
    np.testing.assert_allclose(external(mech, PHI_T, 1.0).force, magnitude[:, None] * unit, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(external(mech, PHI_T, -1.0).force, 0.0)  # x_B increasing: idle


def test_directed_force_with_a_cycle_table_over_the_range():
    """13 values at the positions 30, 40, ..., 150 deg of the range (12 positions by default),
    linear in the input angle between them."""
    values = [10.0 * i * i for i in range(1, 14)]
    mech = tangent(force_entry(between='["O", "B"]', cycle=values))
    phi = np.radians([30.0, 35.0, 90.0, 145.0, 150.0])
    expected = np.array([10.0, 25.0, 10 * 49, (10 * 144 + 10 * 169) / 2, 10 * 169])
    unit = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    np.testing.assert_allclose(external(mech, phi, 1.0).force, expected[:, None] * unit, rtol=1e-12)


def test_directed_diagram_in_the_cycle_dynamics():
    """A press force along B -> O of 1000 N on the working stroke only (x_B increasing): its work
    over a cycle is -1000 N x (|OB|_max - |OB|_min) = -1000 x 2 l1 (|OB| = l1 + l2 and l2 - l1 at the
    stroke ends), so the exact method's driving moment is 1000 x 2 l1 / (2 pi)."""
    mech = press({"gravity": [0, 0], "forces": [
        {"point": "B", "link": "3", "between": ["B", "O"],
         "diagram": {"quantity": "B.x", "working": "+", "fractions": [0, 1], "values": [1000, 1000]}}]},
        {"mean_speed": 10.0, "delta": 0.05, "inertia_0": 5.0})
    law = exact_method(mech)
    assert law.driving_moment == pytest.approx(1000 * 2 * L1 / (2 * np.pi), rel=1e-6)


BAD_DIRECTED = {
    "magnitude without a direction": (dict(magnitude=5.0), ["magnitude = 5.0", "between", "along_link"]),
    "force vector with a direction": (dict(between='["O", "B"]', force=[1.0, 0.0]), ["force = [1.0, 0.0]",
                                                                                     "magnitude"]),
    "both directions": (dict(between='["O", "B"]', along_link='"1"', magnitude=5.0), ["not both"]),
    "angle without along_link": (dict(angle_deg=30, magnitude=5.0), ["angle_deg", "along_link"]),
    "unknown point in between": (dict(between='["O", "Q"]', magnitude=5.0), ["between", "'Q'"]),
    "one point twice": (dict(between='["B", "B"]', magnitude=5.0), ["between", "twice"]),
    "unknown link": (dict(along_link='"7"', magnitude=5.0), ["along_link", "'7'"]),
    "no magnitude": (dict(between='["O", "B"]'), ["exactly one of 'magnitude'"]),
    "diagram without quantity": (dict(between='["O", "B"]', diagram='{ working = "+", fractions = [0, 1], '
                                      'values = [1, 1] }'), ["quantity", "None"]),
    "diagram with opposes": (dict(between='["O", "B"]', diagram='{ quantity = "B.x", working = "+", '
                                  'fractions = [0, 1], values = [1, 1], opposes = false }'), ["opposes"]),
    "bad magnitude": (dict(between='["O", "B"]', magnitude="1e300"), ["magnitude", "1e+300"]),
}


@pytest.mark.parametrize("case", list(BAD_DIRECTED))
def test_directed_forces_declared_wrongly_are_refused(case):
    keys, needles = BAD_DIRECTED[case]
    with pytest.raises(SchemeError) as info:
        tangent(force_entry(**keys))
    (problem,) = info.value.problems
    for needle in ["tangent.toml", "forces[0]", *needles]:
        assert needle in problem, (needle, problem)


def test_between_points_that_coincide_is_refused():
    """An isosceles slider-crank (crank = rod = 0.1 m, guide through O): B = O where cos(phi) <= 0
    on the branch B = l cos(phi) + l |cos(phi)|, so the line O -> B is undefined there."""
    data = to_dict(linkage.load("slider_crank"))
    data["links"]["0"]["guides"]["slide"]["through"] = [0.0, 0.0]
    data["links"]["1"]["points"]["A"] = [0.1, 0.0]
    data["links"]["2"]["points"] = {"A": [0.0, 0.0], "B": [0.1, 0.0], "S2": [0.05, 0.0]}
    data["assembly"] = {"B": {"from": "A", "towards": 0.0}}
    data["loads"] = {"forces": [{"point": "B", "link": "3", "between": ["O", "B"], "magnitude": 1.0}]}
    with pytest.raises(SchemeError, match=r"forces\[0\].*between \['O', 'B'\].*coincide at phi = "):
        from_dict(data)


# ----------------------------------------------------------------------------------------------
# 3. input range
# ----------------------------------------------------------------------------------------------

RL1, RL2 = 0.2, 0.1  # rocker slider-crank: the crank is longer than the rod, |sin phi| <= 1/2
ROCKER = slider_crank_toml(RL1, RL2, name="rocker_slider", header='output = { quantity = "B.x", start = "max" }\n'
                           'range_deg = [-20, 25]')


def x_rocker(phi):
    return RL1 * np.cos(phi) + np.sqrt(RL2**2 - (RL1 * np.sin(phi)) ** 2)


def test_tables_and_extremes_over_the_range():
    mech = tangent()
    phi = linkage.table_angles(mech, 12)
    np.testing.assert_allclose(np.degrees(phi), 30.0 + 10.0 * np.arange(13), rtol=0, atol=1e-12)
    ext = linkage.extreme_positions(mech, "B.x")  # monotonic over the range: its ends
    assert (math.degrees(ext.phi_max), math.degrees(ext.phi_min)) == pytest.approx((30.0, 150.0), abs=1e-12)
    assert (ext.value_max, ext.value_min) == pytest.approx((H / math.tan(math.pi / 6), -H / math.tan(math.pi / 6)),
                                                           abs=1e-15)
    # |OB| = h / sin(phi): its minimum is a root of the analog inside the range
    ext = linkage.extreme_positions(tangent(**{"[30, 150]": "[30, 120]"}), "slot.s")
    assert math.degrees(ext.phi_min) == pytest.approx(90.0, abs=1e-9) and ext.value_min == pytest.approx(H, rel=1e-14)
    assert math.degrees(ext.phi_max) == pytest.approx(30.0, abs=1e-12) and ext.value_max == pytest.approx(2 * H)
    # the rocker input: the maximum l1 + l2 at phi = 0 inside, the minimum at the range end 25 deg
    rocker = linkage.loads(ROCKER)
    ext = linkage.extreme_positions(rocker)
    assert ext.phi_max == pytest.approx(0.0, abs=1e-9) and ext.value_max == pytest.approx(RL1 + RL2, rel=1e-14)
    assert math.degrees(ext.phi_min) == pytest.approx(25.0, abs=1e-12)
    assert ext.value_min == pytest.approx(x_rocker(math.radians(25.0)), rel=1e-14)
    # a force diagram over the range measures its stroke between those ends
    loaded = linkage.loads(ROCKER + '\n[[loads.forces]]\npoint = "B"\nlink = "3"\n'
                           'diagram = { along = "x", working = "+", fractions = [0, 1], values = [0, 100] }\n')
    (force,) = loads_of(loaded).forces
    assert force.force.stroke_ends == pytest.approx((x_rocker(math.radians(25.0)), RL1 + RL2), rel=1e-14)


def test_range_written_backwards_runs_backwards_and_round_trips():
    mech = tangent(**{"[30, 150]": "[150, 30]"})
    np.testing.assert_allclose(np.degrees(linkage.table_angles(mech, 4)), [150, 120, 90, 60, 30], atol=1e-12)
    assert linkage.loads(linkage.dumps(mech)) == mech
    assert linkage.loads(linkage.dumps(mech)).input_range == pytest.approx(np.radians([150, 30]))
    with pytest.raises(InputError, match=r"range \[150, 30\] deg.*start"):
        linkage.table_angles(mech, 4, "max")


@pytest.mark.parametrize("text, needles", [
    ("range_deg = [-20, 40]", ["range_deg = [-20, 40]", "cannot be assembled at phi = 30", "..40 deg",
                               "assembles at -20..30"]),
    ("range_deg = [10, 10]", ["range_deg = [10, 10]", "more than 0 and less than 360", "0 deg"]),
    ("range_deg = [0, 360]", ["range_deg = [0, 360]", "360 deg"]),
    ("range_deg = [-20]", ["range_deg", "expected [a, b]", "[-20]"]),
    ("range_deg = [-20, 2e6]", ["range_deg", "2000000"]),
    ("range = [-0.2, 0.2]\nrange_deg = [-20, 20]", ["either 'range' (rad) or 'range_deg' (deg)"]),
])
def test_bad_ranges_are_refused_naming_the_file_and_the_value(tmp_path, text, needles):
    path = tmp_path / "rocker.toml"
    path.write_text(ROCKER.replace("range_deg = [-20, 25]", text))
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    (problem,) = info.value.problems
    for needle in ["rocker.toml", *needles]:
        assert needle in problem, (needle, problem)


def test_start_deg_with_a_range_is_refused():
    with pytest.raises(SchemeError, match=r"tangent\.toml: dynamics: start_deg = 40: .*range_deg = \[30, 150\]"):
        tangent("\n[dynamics]\nmean_speed = 1.0\nstart_deg = 40\n")


def test_cycle_dynamics_refuse_a_partial_range():
    mech = tangent('\n[dynamics]\nmean_speed = 2.0\ndelta = 0.1\ninertia_0 = 1.0\ninitial_speed = 1.0\n'
                   '[dynamics.motor]\nkind = "constant"\nmoment = 1.0\n')
    for call in (course_method, exact_method, simulate, steady_state, run_dynamics):
        with pytest.raises(DynamicsInputError, match=r"'tangent'.*turn fully.*range_deg = \[30, 150\]"):
            call(mech)


def test_cli_range(capsys):
    # --range on a scheme that turns fully: the input angles from A to B in N steps
    code, out, err = run(capsys, "analyze", "four_bar", "--range", "10", "100", "-n", "3", "-f", "csv")
    assert code == 0, err
    np.testing.assert_allclose(np.degrees(read_csv(out)["1.theta"]), [10, 40, 70, 100], atol=1e-9)
    code, out, err = run(capsys, "analyze", "four_bar", "--range", "10", "370")
    assert code == 2 and "--range" in err and "360" in err
    code, out, err = run(capsys, "analyze", "four_bar", "--range", "10", "20", "--start", "5")
    assert code == 2 and "not allowed with argument" in err


def test_cli_uses_the_scheme_range(capsys, tmp_path):
    path = tmp_path / "tangent.toml"
    path.write_text(TANGENT + force_entry(between='["O", "B"]', magnitude=100.0))
    code, out, err = run(capsys, "forces", path, "-n", "4", "-f", "csv")
    assert code == 0, err
    table = read_csv(out)
    phi = np.radians([30.0, 60.0, 90.0, 120.0, 150.0])
    np.testing.assert_allclose(table["balancing_moment"], 100 * H * np.cos(phi) / np.sin(phi) ** 2,
                               rtol=1e-9, atol=1e-9)
    code, out, err = run(capsys, "analyze", path, "--start", "40")
    assert code == 2 and "range_deg = [30, 150]" in err and "--start" in err
    code, out, err = run(capsys, "dynamics", path)
    assert code == 2 and "range_deg" in err


# ----------------------------------------------------------------------------------------------
# 4. start from rest
# ----------------------------------------------------------------------------------------------

I0, M0, W0 = 2.0, 30.0, 50.0  # constant inertia (kg m^2), stall moment (N m), no-load speed (rad/s)


def rest_machine(motor=None, initial="initial_speed = 0.0", extra_loads=None):
    """The press with massless moving links and no gravity: a constant reduced inertia I0 and no
    resistance (unless ``extra_loads``)."""
    motor = motor or {"kind": "linear", "stall_moment": M0, "no_load_speed": W0}
    key, value = (s.strip() for s in initial.split("="))
    return press({"gravity": [0, 0], **(extra_loads or {})},
                 {"mean_speed": 40.0, "inertia_0": I0, key: float(value), "cycles": 20, "motor": motor},
                 massless=True)


def test_start_from_rest_matches_the_closed_form():
    """I dw/dt = M0 (1 - w / w0): w = w0 (1 - exp(-t / tau)), psi = w0 t - w0 tau (1 - exp(-t / tau)),
    tau = I w0 / M0."""
    mech = rest_machine(initial="initial_rpm = 0")
    assert dynamics_of(mech).initial_speed == 0.0
    tr = simulate(mech)
    tau = I0 * W0 / M0
    assert tr.t[0] == 0.0 and tr.omega[0] == 0.0 and tr.psi[0] == 0.0
    np.testing.assert_allclose(tr.omega, W0 * (1 - np.exp(-tr.t / tau)), rtol=0, atol=1e-8 * W0)
    np.testing.assert_allclose(tr.psi, W0 * tr.t - W0 * tau * (1 - np.exp(-tr.t / tau)), rtol=1e-7, atol=1e-9)
    assert tr.psi[-1] == pytest.approx(2 * np.pi * 20)
    # the dense solution psi -> [T, t], before and after the switch to the energy form (1 deg)
    psi_exact = lambda t: W0 * t - W0 * tau * (1 - math.exp(-t / tau))  # noqa: E731
    for t in (0.01, 0.05, 0.5, 3.0):
        energy, time = tr.sol(psi_exact(t))
        assert time == pytest.approx(t, rel=1e-6)
        assert energy == pytest.approx(I0 * (W0 * (1 - math.exp(-t / tau))) ** 2 / 2, rel=1e-6)


def test_start_from_rest_needs_a_starting_torque(tmp_path):
    for motor, moment in (({"kind": "linear", "stall_moment": 0.0, "no_load_rpm": 400}, "0"),
                          ({"kind": "constant", "moment": -3.0}, "-3")):
        data = to_dict(rest_machine())
        data["dynamics"]["motor"] = motor
        data["dynamics"].pop("initial_speed")
        data["dynamics"]["initial_rpm"] = 0
        path = tmp_path / "stalled.toml"
        path.write_text(linkage.model.scheme._toml_table(data, ()))  # the TOML writer of linkage.dumps
        with pytest.raises(SchemeError) as info:
            linkage.load(path)
        (problem,) = info.value.problems
        for needle in ("stalled.toml", "dynamics", "initial_rpm = 0", "starting torque",
                       f"moment at rest is {moment} N m"):
            assert needle in problem, (needle, problem)
    # no motor declared: the constant moment that balances the cycle is 0 here: no starting torque
    data = to_dict(rest_machine())
    data["dynamics"].pop("motor")
    with pytest.raises(DynamicsInputError, match=r"initial_speed = 0 .*starting torque.*balances the cycle"):
        simulate(from_dict(data))
    # a negative start speed is still refused
    with pytest.raises(SchemeError, match=r"initial_speed .* must be 0 \(from rest\) or .*got -1"):
        rest_machine(initial="initial_speed = -1")


def test_a_machine_whose_resistance_exceeds_the_starting_torque_does_not_start():
    mech = rest_machine(extra_loads={"moments": [{"link": "1", "moment": -50.0}]})  # 50 N m > M0 = 30 N m
    with pytest.raises(DynamicsError, match=r"does not start from rest: the starting torque 30 N m does not "
                                            r"overcome the resisting moment 50 N m"):
        simulate(mech)


def test_induction_motor_from_rest():
    """Kloss at slip 1: M = 2 M_k / (1 / S_k + S_k) with M_k = lambda M_nom, S_k = S_nom (lambda +
    sqrt(lambda^2 - 1)); at the crank U eta M. The flying shears' motor: 90 W, 1500 / 1400 rpm,
    lambda = 2.2, U = 23.5, eta = 0.9."""
    shears = linkage.load("flying_shears")
    spec = dynamics_of(shears)
    m_nom = 90.0 / (1400 * 2 * math.pi / 60)
    s_k = (100 / 1500) * (2.2 + math.sqrt(2.2**2 - 1))
    by_hand = 23.5 * 0.9 * 2 * 2.2 * m_nom / (1 / s_k + s_k)
    assert starting_moment(spec.motor) == pytest.approx(by_hand, rel=1e-13)
    text = Path(linkage.shipped_schemes()["flying_shears"]).read_text().replace("initial_rpm = 6", "initial_rpm = 0")
    mech = linkage.loads(text)
    tr = simulate(mech, cycles=2)
    assert tr.omega[0] == 0.0 and np.all(np.diff(tr.t) > 0) and np.all(tr.omega[1:] > 0)
    assert tr.psi[-1] == pytest.approx(4 * np.pi)


def test_motor_speed_in_rpm():
    data = to_dict(rest_machine())
    data["dynamics"]["motor"] = {"kind": "linear", "stall_moment": M0, "no_load_rpm": 600, "ratio": 2.0}
    motor = dynamics_of(from_dict(data)).motor
    assert motor == LinearMotor(M0, 600 * 2 * math.pi / 60, 2.0)
    data["dynamics"]["motor"]["no_load_speed"] = 60.0
    with pytest.raises(SchemeError, match=r"motor \(linear\): give either no_load_speed \(rad/s\) or no_load_rpm"):
        from_dict(data)


# ----------------------------------------------------------------------------------------------
# 5. refuse what cannot be meant
# ----------------------------------------------------------------------------------------------


def test_cycle_table_of_the_wrong_length_is_refused(tmp_path):
    text = Path(linkage.shipped_schemes()["course_slider_crank"]).read_text()
    path = tmp_path / "press.toml"
    path.write_text(re.sub(r"cycle = \[.*\]", "cycle = [1, 2, 3]", text))
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    (problem,) = info.value.problems
    for needle in ("press.toml", "loads", "forces[0]", "'B'", "cycle has 3 values, expected 13",
                   "positions = 12"):
        assert needle in problem, (needle, problem)
    # 13 values for a table of 6 positions (7 values) is refused too
    path.write_text(text.replace("positions = 12", "positions = 6"))
    with pytest.raises(SchemeError, match=r"press\.toml: loads: forces\[0\].*13 values, expected 7"):
        linkage.load(path)


def test_assembly_condition_no_branch_meets_is_refused(tmp_path):
    """B from O towards 90 deg on a slider guided along y = 0: (B - O) . (0, 1) = 0 on both branches."""
    text = Path(linkage.shipped_schemes()["slider_crank"]).read_text()
    text = text.replace("through = [0.0, 0.01335]", "through = [0.0, 0.0]").replace("towards_deg = 0",
                                                                                    "towards_deg = 90")
    path = tmp_path / "flat.toml"
    path.write_text(text)
    with pytest.raises(SchemeError, match=r"flat\.toml: .*assembly of point 'B' .*does not tell the two "
                                          r"branches .* apart"):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# 6. the format reference: every TOML example loads
# ----------------------------------------------------------------------------------------------


def readme_examples():
    """(first line, text) of every ```toml block of schemes/README.md."""
    blocks = re.findall(r"```toml\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    return [(b.splitlines()[0], b) for b in blocks]


@pytest.mark.parametrize("first, text", readme_examples(), ids=[f for f, _ in readme_examples()])
def test_readme_examples_load(first, text):
    """A block is a complete scheme, or a fragment whose first line says '# added to <scheme>':
    its sections replace the scheme's."""
    found = re.match(r"# added to (\S+)", first)
    if found is None:
        data = tomllib.loads(text)
        if "links" not in data:
            pytest.skip("a fragment of an entry (shown inside a larger table)")
        from_dict(data)
        return
    base = found.group(1)
    data = tomllib.loads(TANGENT if base == "tangent" else ROCKER if base == "rocker_slider" else
                         Path(linkage.shipped_schemes()[base]).read_text())
    data.update(tomllib.loads(text))
    from_dict(data)
