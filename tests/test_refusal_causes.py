"""A refusal names its real cause: an input that cannot turn fully is said to be one, first.

A crank that cannot turn fully (a rod too short, a crank too long, a guide too far, a four-bar
that is not a crank-rocker by Grashof) is refused in words that say so -- the angles where the
mechanism assembles and the dimensional reason with the numbers -- by ``linkage.load`` (a force
diagram that needs the whole turn), by the CLI (``analyze``, ``forces``, exit 2 without a
traceback), by the feasibility check and by ``linkage variants`` (linkage/kinematics/turning.py,
full_turn.py). The oracles are computed here in closed form: where the slider-crank's rod reaches
the guide's line, |r sin φ - e| <= l, and where a four-bar's coupler and rocker bridge |AC|, by
the cosine law; for a six-bar, its four-bar solved here by the intersection of two circles.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import linkage
from assur.base import CANNOT_ASSEMBLE
from linkage.course.template import template_path
from linkage.errors import SchemeError
from linkage.kinematics.feasibility import Requirements, check
from linkage.kinematics.full_turn import input_cannot_turn
from linkage.kinematics.inputs import input_poses
from linkage.kinematics.turning import turning_reason
from linkage.model.scheme import scheme_path
from linkage.structure import structure_of

SLIDER_CRANK = scheme_path("slider_crank").read_text(encoding="utf-8")
FOUR_BAR = scheme_path("four_bar").read_text(encoding="utf-8")
SIX_BAR = scheme_path("six_bar").read_text(encoding="utf-8")

#: the slider-crank's resistance: a diagram over the working stroke of B.x (it needs the whole turn)
PRESS_FORCE = """
[[loads.forces]]
point = "B"
link = "3"
diagram = { along = "x", working = "+", fractions = [0, 1], values = [0, 1000] }
"""
#: the four-bar's resisting moment on the rocker over its swing
ROCKER_MOMENT = """
[[loads.moments]]
link = "3"
diagram = { working = "+", fractions = [0, 1], values = [0, 10] }
"""
SPAN = re.compile(r"from (-?\d+(?:\.\d+)?)° to (-?\d+(?:\.\d+)?)°( \(through 0°\))?")


def slider_crank(crank: float, rod: float, offset: float = 0.01335, loads: str = PRESS_FORCE) -> str:
    """The shipped slider-crank with the crank OA, the rod AB and the guide's line y = offset."""
    for old in ("length = 0.0742", "length = 0.2225", "through = [0.0, 0.01335]"):
        assert old in SLIDER_CRANK
    return (SLIDER_CRANK.replace("length = 0.0742", f"length = {crank!r}")
            .replace("length = 0.2225", f"length = {rod!r}")
            .replace("through = [0.0, 0.01335]", f"through = [0.0, {offset!r}]") + loads)


def four_bar(crank: float, rocker: float, ground: float, loads: str = ROCKER_MOMENT) -> str:
    """The shipped four-bar (coupler AB = 0.3 m) with the crank OA, the rocker CB and C = (ground, 0)."""
    for old in ("length = 0.1\n", "length = 0.25\n", "C = [0.3, 0.0]", "length = 0.3\n"):
        assert old in FOUR_BAR
    return (FOUR_BAR.replace("length = 0.1\n", f"length = {crank!r}\n")
            .replace("length = 0.25\n", f"length = {rocker!r}\n")
            .replace("C = [0.3, 0.0]", f"C = [{ground!r}, 0.0]") + loads)


def slider_crank_stops(r: float, l: float, e: float) -> tuple[float, float]:
    """The one interval of φ (deg, increasing, within a turn) where |r sin φ - e| > l: the rod
    AB = l cannot reach the guide's line y = e from A = r (cos φ, sin φ); here r sin φ - e < -l."""
    assert (l + e) / r >= 1.0 > (e - l) / r > -1.0      # only the lower side can fail
    low = math.degrees(math.asin((l - e) / r))           # sin φ < -(l - e) / r
    return 180.0 + low, 360.0 - low


def four_bar_stops(r: float, coupler: float, rocker: float, ground: float) -> tuple[float, float]:
    """The interval of φ (deg) where |AC| = sqrt(r^2 + d^2 - 2 r d cos φ) > AB + CB (cosine law)."""
    cos_limit = (r**2 + ground**2 - (coupler + rocker) ** 2) / (2 * r * ground)
    assert -1.0 < cos_limit < 1.0 and (r**2 + ground**2 - 2 * r * ground) ** 0.5 >= abs(coupler - rocker)
    limit = math.degrees(math.acos(cos_limit))
    return limit, 360.0 - limit


def spans_in(message: str) -> list[tuple[float, float, bool]]:
    """The spans ``(from, to, through 0)`` of φ (deg) a message says the mechanism assembles over."""
    return [(float(a), float(b), bool(through)) for a, b, through in SPAN.findall(message)]


def assert_assembles_outside(message: str, stops: tuple[float, float]) -> None:
    """The message says the input cannot turn fully and the mechanism assembles from the end of
    ``stops`` round through 0° to its start (to the 0.01° the message gives)."""
    assert "the input link '1' cannot turn fully: the mechanism assembles only for φ from" in message
    (start, end, through), = spans_in(message)
    assert through
    assert start == pytest.approx(stops[1], abs=0.006)
    assert end == pytest.approx(stops[0], abs=0.006)


def refused(tmp_path: Path, text: str, name: str = "scheme") -> str:
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    return str(info.value)


# ----------------------------------------------------------------------------------------------
# linkage.load: a force diagram over the stroke of a crank that cannot turn fully
# ----------------------------------------------------------------------------------------------


def test_a_rod_too_short_is_refused_as_a_crank_that_cannot_turn(tmp_path):
    message = refused(tmp_path, slider_crank(0.2, 0.19))
    assert_assembles_outside(message, slider_crank_stops(0.2, 0.19, 0.01335))
    assert "because the rod AB = 0.19 m is shorter than the crank OA plus the offset" in message
    assert "0.2 + 0.01335 = 0.21335 m" in message
    assert "forces[0] (point 'B') cannot follow the working cycle" in message
    assert "stroke 0" not in message and "never taken" not in message


def test_a_crank_too_long_is_refused_as_a_crank_that_cannot_turn(tmp_path):
    message = refused(tmp_path, slider_crank(0.22, 0.2225))
    assert_assembles_outside(message, slider_crank_stops(0.22, 0.2225, 0.01335))
    assert "the rod AB = 0.2225 m is shorter than the crank OA plus the offset" in message
    assert "0.22 + 0.01335 = 0.23335 m" in message


def test_a_guide_too_far_from_the_crank_is_refused_as_a_crank_that_cannot_turn(tmp_path):
    # the guide's line at y = 0.2: A = 0.0742 (cos φ, sin φ) comes within AB = 0.2225 m of it only
    # where 0.2 - 0.0742 sin φ <= 0.2225
    message = refused(tmp_path, slider_crank(0.0742, 0.2225, 0.2))
    assert_assembles_outside(message, slider_crank_stops(0.0742, 0.2225, 0.2))
    assert "0.0742 + 0.2 = 0.2742 m" in message


def test_a_crank_too_long_for_the_assembly_condition_is_refused_as_a_crank_that_cannot_turn(tmp_path):
    # r = 0.25 > l + e: B cannot reach the guide on either side, so the two branches satisfy
    # "B right of O" equally often; the cause is the turn: r sin φ - e must stay within +-l
    message = refused(tmp_path, slider_crank(0.25, 0.2225, loads=""))
    assert "the input link '1' cannot turn fully" in message
    high = math.degrees(math.asin((0.2225 + 0.01335) / 0.25))      # r sin φ - e <= l
    low = math.degrees(math.asin((0.2225 - 0.01335) / 0.25))       # r sin φ - e >= -l
    found = sorted((a, b) for a, b, _ in spans_in(message))
    assert found == [pytest.approx((180 - high, 180 + low), abs=0.006),
                     pytest.approx((360 - low, high), abs=0.006)]
    assert "0.25 + 0.01335 = 0.26335 m" in message
    # the turn is said first; the condition it leaves undecided only after it
    assert "does not tell" not in message or message.index("cannot turn fully") < message.index("does not tell")


def test_a_four_bar_that_is_not_grashof_is_refused_as_a_crank_that_cannot_turn(tmp_path):
    # OA = 0.2, AB = 0.3, CB = 0.22, OC = 0.35: s + l = 0.2 + 0.35 = 0.55 > p + q = 0.22 + 0.3 = 0.52
    message = refused(tmp_path, four_bar(0.2, 0.22, 0.35))
    assert_assembles_outside(message, four_bar_stops(0.2, 0.3, 0.22, 0.35))
    assert "the four-bar OABC is not a Grashof chain" in message
    assert "crank OA = 0.2 m and frame OC = 0.35 m, add up to s + l = 0.55 m" in message
    assert "rocker CB + coupler AB = 0.52 m" in message
    assert "moments[0] (link '3') cannot follow the working cycle" in message


def test_a_grashof_four_bar_whose_crank_is_not_the_shortest_link_cannot_turn(tmp_path):
    # OA = 0.28, AB = 0.3, CB = 0.25, OC = 0.3: s + l = 0.25 + 0.3 <= 0.28 + 0.3, the rocker the
    # shortest: the crank rocks where |AC| stays within [AB - CB, AB + CB] = [0.05, 0.55]
    message = refused(tmp_path, four_bar(0.28, 0.25, 0.3))
    d2 = lambda phi: 0.28**2 + 0.3**2 - 2 * 0.28 * 0.3 * math.cos(math.radians(phi))
    near = math.degrees(math.acos((0.28**2 + 0.3**2 - 0.05**2) / (2 * 0.28 * 0.3)))     # |AC| = 0.05
    far = math.degrees(math.acos((0.28**2 + 0.3**2 - 0.55**2) / (2 * 0.28 * 0.3)))      # |AC| = 0.55
    assert d2(near) == pytest.approx(0.05**2) and d2(far) == pytest.approx(0.55**2)
    found = [(a, b) for a, b, _ in spans_in(message)]
    assert found == [pytest.approx((near, far), abs=0.006), pytest.approx((360 - far, 360 - near), abs=0.006)]
    assert ("is a Grashof chain (s + l = 0.55 m <= p + q = 0.58 m) whose shortest link is the rocker CB = "
            "0.25 m, not the crank OA = 0.28 m nor the frame OC = 0.3 m") in message


def test_another_group_that_cannot_close_gives_its_own_reason():
    # the six-bar's ram guide raised to y = 0.65: the rod DF = 0.4 m reaches it only while D.y >= 0.25
    mech = linkage.loads(SIX_BAR.replace("through = [0.0, 0.3]", "through = [0.0, 0.65]"))

    def d_y(phi: float) -> float:      # the four-bar solved here: B on the left of A -> C, D on CB
        A, C = 0.1 * np.array([math.cos(phi), math.sin(phi)]), np.array([0.3, 0.0])
        d = np.linalg.norm(C - A)
        along = (0.3**2 - 0.25**2 + d**2) / (2 * d)
        e = (C - A) / d
        B = A + along * e + math.sqrt(0.3**2 - along**2) * np.array([-e[1], e[0]])
        return float((C + 0.35 / 0.25 * (B - C))[1])

    grid = np.radians(np.arange(0.0, 360.0, 1.0))
    low = np.array([d_y(x) for x in grid]) < 0.25
    edges = [brentq(lambda x: d_y(x) - 0.25, grid[i], grid[i + 1]) for i in np.flatnonzero(np.diff(low))]
    stops = sorted(np.degrees(edges))
    assert len(stops) == 2
    message = input_cannot_turn(mech)
    assert_assembles_outside(message, (stops[0], stops[1]))
    assert "group II-RRP(4,5) cannot close" in message and "the link DF is 0.4 m long" in message


# ----------------------------------------------------------------------------------------------
# the function the assembly plans call, and the feasibility check: the same words
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("text", [slider_crank(0.2, 0.19, loads=""), four_bar(0.2, 0.22, 0.35, loads="")],
                         ids=["slider_crank", "four_bar"])
def test_the_assembly_plans_and_the_feasibility_check_say_it_in_the_same_words(text):
    mech = linkage.loads(text)           # no diagram: it loads, and analyses where it assembles
    sentence = input_cannot_turn(mech)
    assert sentence is not None and "cannot turn fully" in sentence
    # as the assembly plans call it: the first group, the known links' poses over their sweep
    structure = structure_of(mech)
    phi = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)
    poses = input_poses(mech, structure, phi)
    group = structure.groups[0]
    assembled = group.position(poses, group.branches[0]).status != CANNOT_ASSEMBLE
    assert not assembled.all()
    assert turning_reason(mech, group, poses, phi, assembled) == sentence
    verdict = check(mech, Requirements())
    assert (verdict.rule, verdict.reason) == ("full_rotation", sentence)
    stroke = check(mech, Requirements(full_rotation=False, no_change_point=False, non_singular=False,
                                      stroke=(0.0, 1.0)))
    assert stroke.reason == f"the stroke of {mech.output.quantity} cannot be measured: {sentence}"


def test_a_mechanism_that_turns_fully_is_not_refused():
    assert input_cannot_turn(linkage.load("slider_crank")) is None
    assert input_cannot_turn(linkage.load("four_bar")) is None


# ----------------------------------------------------------------------------------------------
# the command line
# ----------------------------------------------------------------------------------------------


CASES = {
    "rod_too_short": (slider_crank(0.2, 0.19), slider_crank_stops(0.2, 0.19, 0.01335)),
    "crank_too_long": (slider_crank(0.22, 0.2225), slider_crank_stops(0.22, 0.2225, 0.01335)),
    "guide_too_far": (slider_crank(0.0742, 0.2225, 0.2), slider_crank_stops(0.0742, 0.2225, 0.2)),
    "not_grashof": (four_bar(0.2, 0.22, 0.35), four_bar_stops(0.2, 0.3, 0.22, 0.35)),
}


@pytest.mark.parametrize("command", ["analyze", "forces"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_cli_refuses_a_crank_that_cannot_turn_naming_the_cause(linkage_run, tmp_path, case, command):
    text, stops = CASES[case]
    path = tmp_path / f"{case}.toml"
    path.write_text(text, encoding="utf-8")
    run = linkage_run(command, str(path))
    assert run.status == 2
    assert "Traceback" not in run.err and run.out == ""
    error, = [line for line in run.err.splitlines() if line.startswith("linkage: error:")]
    assert f"{case}.toml: loads: the input link '1' cannot turn fully" in error
    assert_assembles_outside(error, stops)


def test_the_cli_names_the_turn_before_the_extreme_positions(linkage_run, tmp_path):
    # no load needs the turn, but position 1 does: the rocker's largest angle over a turn
    path = tmp_path / "rocking_crank.toml"
    path.write_text(four_bar(0.28, 0.25, 0.3, loads=""), encoding="utf-8")
    run = linkage_run("analyze", str(path))
    assert run.status == 2 and "Traceback" not in run.err
    assert run.err.startswith("linkage: error: the input link '1' cannot turn fully: the mechanism assembles only")
    assert "shortest link is the rocker CB = 0.25 m" in run.err
    assert "so '3.theta' of mechanism 'four_bar' has no extreme position" in run.err


def test_variants_from_a_table_name_the_turn_as_the_broken_rule(linkage_run, tmp_path):
    # row 2: crank 0.1, rod 0.1 / 0.95 rounded to 0.1053, offset 0.1 * 0.1 = 0.01 (the template's rounding)
    table = tmp_path / "given.csv"
    table.write_text("crank,ratio,offset_ratio,com_fraction,q_rod,mass_slider,peak_force,rpm,delta,inertia_0\n"
                     "0.1,0.95,0.1,0.35,1600,400,100000,90,0.05,40\n", encoding="utf-8")
    run = linkage_run("variants", "press_slider_crank", "--table", str(table), "--out", "class")
    assert run.status == 2 and "Traceback" not in run.err
    first = run.err.splitlines()[0]
    assert first.startswith(f"linkage: error: {table}: line 2 (crank = 0.1, ratio = 0.95")
    assert "breaks the rule full_rotation = true of [template.require]: the input link '1' cannot turn fully" in first
    assert_assembles_outside(first, slider_crank_stops(0.1, 0.1053, 0.01))
    assert "0.1 + 0.01 = 0.11 m" in first


def test_variants_of_a_crank_rocker_template_name_grashof(linkage_run, tmp_path):
    # O = (0.2, 0.26) above C = (0, 0): OC = 0.328024 m; s + l = 0.2 + 0.328 > AB + CB = 0.3 + 0.22
    table = tmp_path / "given.csv"
    table.write_text("crank,coupler,rocker,arm_ratio,frame_x,frame_y,rod,q_link,mass_ram,force,approach,rpm,delta,"
                     "inertia_0\n0.2,0.3,0.22,1.5,0.2,0.26,0.35,25,40,6000,0.4,70,0.05,1.0\n", encoding="utf-8")
    run = linkage_run("variants", "press_crank_rocker", "--table", str(table), "--out", "class")
    assert run.status == 2 and "Traceback" not in run.err
    first = run.err.splitlines()[0]
    assert "breaks the rule full_rotation = true" in first and "is not a Grashof chain" in first
    # |AC| = |O + r e(φ)| <= AB + CB = 0.52: cos(φ - α) <= (0.52^2 - |O|^2 - r^2) / (2 r |O|)
    alpha, norm = math.atan2(0.26, 0.2), math.hypot(0.2, 0.26)
    half = math.acos((0.52**2 - norm**2 - 0.2**2) / (2 * 0.2 * norm))
    assert_assembles_outside(first, (math.degrees(alpha - half), math.degrees(alpha + half)))
    assert f"frame OC = {norm:.6g} m" in first


TEMPLATE_PARAMETERS = """
[template.parameters]
crank = { value = 0.1, unit = "m", label = "crank length OA" }
ratio = { values = [0.3, 0.95], label = "crank-to-rod ratio OA / AB" }
rod = { value = "= crank / ratio", unit = "m", label = "rod length AB", round = 4 }
offset = { value = 0.01, unit = "m", label = "offset e of the guide above O" }
rod_com = { value = "= 0.35 * rod", unit = "m", label = "AS2", round = 4 }
mass_rod = { value = "= 1600 * rod", unit = "kg", label = "mass of the rod", round = 1 }
mass_crank = { value = 40, unit = "kg", label = "mass of the crank" }
mass_slider = { value = 400, unit = "kg", label = "mass of the slider" }
inertia_rod = { value = "= mass_rod * rod ** 2 / 12", unit = "kg m^2", label = "J_S2", round = 3 }
peak_force = { value = 100000, unit = "N", label = "peak force" }
rpm = { value = 90, unit = "rpm", label = "speed" }
delta = { value = 0.05, label = "delta" }
inertia_0 = { value = 40.0, unit = "kg m^2", label = "I0" }
"""


def test_drawn_variants_count_and_tell_a_crank_that_cannot_turn(linkage_run, tmp_path):
    # two combinations: λ = 0.3 turns, λ = 0.95 (rod 0.1053 m < 0.1 + 0.01 m) does not
    shipped = template_path("press_slider_crank").read_text(encoding="utf-8")
    start, end = shipped.index("\n[template.parameters]\n"), shipped.index("\n[template.require]\n")
    template = tmp_path / "small_press.toml"
    template.write_text(shipped[:start] + TEMPLATE_PARAMETERS + shipped[end:], encoding="utf-8")
    run = linkage_run("variants", str(template), "--count", "2", "--seed", "3", "--out", "class")
    assert run.status == 2 and "Traceback" not in run.err
    assert "rejected by rule: full_rotation 1" in run.err
    note, = [line for line in run.err.splitlines() if line.startswith("linkage: note: e.g. full_rotation: ")]
    assert_assembles_outside(note, slider_crank_stops(0.1, 0.1053, 0.01))
    selection = json.loads((run.cwd / "class" / "selection.json").read_text(encoding="utf-8"))
    assert selection["rejected"]["full_rotation"] == 1
    assert selection["example_reasons"]["full_rotation"] == note.removeprefix("linkage: note: e.g. full_rotation: ")
