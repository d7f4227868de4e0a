"""Feasibility rules of design variants (linkage.kinematics.feasibility).

Oracles are computed here, independently of the solvers: the four-bar's Grashof condition and
its transmission angle by the cosine law, the offset slider-crank's rod inclination and stroke in
closed form, the rocker's swing from the triangles of its extreme positions, the collinear
positions of the parallelogram, and the angles at which a slotted link lies parallel to a guide.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from _texts import four_bar_toml, slider_crank_toml

import linkage
from linkage.errors import InputError, SchemeError
from linkage.kinematics.feasibility import (
    RULES,
    Requirements,
    Verdict,
    check,
    parse_requirements,
    sweep_angles,
    transmission_angles,
)
from linkage.model.scheme import scheme_path


def four_bar(crank, coupler, rocker, ground, assembly='left_of = ["A", "C"]', **kw):
    return linkage.loads(four_bar_toml(crank, coupler, rocker, ground, assembly, **kw))


def offset_slider_crank(r, rod, e, output=True):
    """Slider-crank with crank r about O = (0, 0) and the slider's guide on the line y = -e."""
    text = slider_crank_toml(r, rod, header='output = "B.x"' if output else "")
    return linkage.loads(text.replace("through = [0.0, 0.0]", f"through = [0.0, {-e!r}]"))


def fold_deg(mu):
    """An angle in rad (0 .. pi) as the acute angle between two lines, deg."""
    mu = np.degrees(mu)
    return np.minimum(mu, 180.0 - mu)


def cosine_law_mu(a, b, c, d, phi):
    """Angle between coupler b and rocker c of the four-bar (crank a, ground d), rad in [0, pi]."""
    return np.arccos((b**2 + c**2 - a**2 - d**2 + 2 * a * d * np.cos(phi)) / (2 * b * c))


def grashof_crank_turns(a, b, c, d):
    """The input crank a turns fully: Grashof (s + l < p + q) and the crank or the ground shortest."""
    s, *middle, l = sorted((a, b, c, d))
    return s + l < sum(middle) and min(a, b, c, d) in (a, d)


# ----------------------------------------------------------------------------------------------
# transmission angles
# ----------------------------------------------------------------------------------------------

CRANK_ROCKER = (1.0, 2.5, 3.0, 4.0)            # s + l = 5 < p + q = 5.5, crank shortest


def test_rrr_transmission_angle_is_the_cosine_law_angle_folded_to_the_acute_one():
    a, b, c, d = CRANK_ROCKER
    phi = np.radians(np.arange(0.0, 360.0, 7.5))
    motion = linkage.analyze(four_bar(a, b, c, d), phi, order=0)
    angles = transmission_angles(motion)
    assert list(angles) == ["II-RRR(2,3)"]
    np.testing.assert_allclose(angles["II-RRR(2,3)"], fold_deg(cosine_law_mu(a, b, c, d, phi)), atol=1e-9)


def test_crank_rocker_minimum_transmission_angle_is_at_phi_0_or_pi():
    a, b, c, d = CRANK_ROCKER
    at_0, at_pi = fold_deg(cosine_law_mu(a, b, c, d, np.array([0.0, np.pi])))
    expected, where = (at_0, 0.0) if at_0 < at_pi else (at_pi, 180.0)
    mech = four_bar(a, b, c, d)
    # 361 angles: pi is not on the grid, the minimum is refined between the angles
    for positions in (360, 361):
        verdict = check(mech, Requirements(positions=positions))
        assert verdict.feasible and verdict.rule is None and verdict.reason is None
        assert verdict.figures["min_transmission_angle_deg"] == pytest.approx(expected, abs=1e-5)
        assert verdict.figures["min_transmission_angle_phi_deg"] == pytest.approx(where, abs=0.05)
        assert verdict.figures["min_transmission_angle_group"] == "II-RRR(2,3)"
    # the raw grid of 361 angles alone would miss the minimum by far more than the tolerance above
    grid = fold_deg(cosine_law_mu(a, b, c, d, sweep_angles(mech, 361)))
    assert grid.min() - expected > 1e-4


def test_transmission_angle_requirement_rejects_just_above_the_minimum_and_passes_just_below():
    a, b, c, d = CRANK_ROCKER
    expected = min(fold_deg(cosine_law_mu(a, b, c, d, np.array([0.0, np.pi]))))
    mech = four_bar(a, b, c, d)
    assert check(mech, Requirements(min_transmission_angle_deg=expected - 0.01)).feasible
    verdict = check(mech, Requirements(min_transmission_angle_deg=round(expected + 0.5)))
    assert (verdict.feasible, verdict.rule) == (False, "transmission_angle")
    assert verdict.reason == (f"the transmission angle of II-RRR(2,3) falls to {expected:.4g} deg at phi = 180 "
                              f"deg, below the required {round(expected + 0.5):g} deg")


def test_offset_slider_crank_transmission_angle_is_90_minus_the_rod_inclination():
    r, rod, e = 0.1, 0.35, 0.03
    mech = offset_slider_crank(r, rod, e)
    phi = np.radians(np.arange(0.0, 360.0, 5.0))
    angles = transmission_angles(linkage.analyze(mech, phi, order=0))
    assert list(angles) == ["II-RRP(2,3)"]
    expected = 90.0 - np.degrees(np.abs(np.arcsin((r * np.sin(phi) + e) / rod)))
    np.testing.assert_allclose(angles["II-RRP(2,3)"], expected, atol=1e-9)
    # smallest where r sin(phi) + e is largest: phi = 90 deg; 361 angles do not contain it
    verdict = check(mech, Requirements(positions=361))
    assert verdict.figures["min_transmission_angle_deg"] == pytest.approx(
        90.0 - math.degrees(math.asin((r + e) / rod)), abs=1e-5)
    assert verdict.figures["min_transmission_angle_phi_deg"] == pytest.approx(90.0, abs=0.05)


def test_prp_transmission_angle_is_the_angle_between_the_slot_and_the_ram_guide():
    mech = linkage.load("slotted_link_two_dyad")     # slot along O3 -> A, ram guide horizontal
    phi = np.radians(np.arange(0.0, 360.0, 10.0))
    angles = transmission_angles(linkage.analyze(mech, phi, order=0))
    assert list(angles) == ["II-PRP(4,5)"]           # the RPR dyad's inner pair is prismatic
    pin = np.column_stack([0.076 * np.cos(phi), 0.12 + 0.076 * np.sin(phi)])    # A; O3 at the origin
    np.testing.assert_allclose(angles["II-PRP(4,5)"], fold_deg(np.arctan2(pin[:, 1], np.abs(pin[:, 0]))),
                               atol=1e-9)


@pytest.mark.parametrize("name", ["slotted_link", "scotch_yoke"])
def test_a_group_with_an_inner_prismatic_pair_has_no_transmission_angle(name):
    mech = linkage.load(name)                        # RPR, RPP
    assert transmission_angles(linkage.analyze(mech, [0.3, 1.0], order=0)) == {}
    assert check(mech).figures["min_transmission_angle_deg"] is None
    verdict = check(mech, Requirements(min_transmission_angle_deg=30.0))
    assert verdict.rule == "transmission_angle" and "no group" in verdict.reason


def test_six_bar_has_one_transmission_angle_per_group():
    motion = linkage.analyze(linkage.load("six_bar"), [0.0, 2.0], order=0)
    assert set(transmission_angles(motion)) == {"II-RRR(2,3)", "II-RRP(4,5)"}


# ----------------------------------------------------------------------------------------------
# full rotation, singular positions, change points
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dims", [(1.0, 3.0, 2.5, 3.0),       # crank-rocker
                                  (2.0, 3.0, 2.5, 1.0),       # double crank (ground shortest)
                                  (2.5, 3.0, 1.0, 3.0),       # rocker shortest: rocker-crank
                                  (2.0, 1.0, 3.0, 2.5),       # coupler shortest: double rocker
                                  (1.0, 1.2, 1.0, 2.0)])      # non-Grashof
def test_grashof_condition_decides_full_rotation(dims):
    a, b, c, d = dims
    verdict = check(four_bar(*dims))
    turns = grashof_crank_turns(*dims)
    assert verdict.feasible == turns
    assert verdict.rule == (None if turns else "full_rotation")
    # the angles where |AC| cannot be bridged by coupler and rocker
    phi = np.radians(np.arange(360.0))
    ac = np.sqrt(a**2 + d**2 - 2 * a * d * np.cos(phi))
    assembles = (ac <= b + c) & (ac >= abs(b - c))
    assert verdict.figures["assembled_positions"] == assembles.sum()


def test_non_grashof_four_bar_is_rejected_by_full_rotation_with_the_angles():
    # |AC|^2 = 1 + 4 - 4 cos(phi) <= (1.2 + 1)^2: it assembles where cos(phi) >= 0.04, |phi| <= 87.7 deg
    verdict = check(four_bar(1.0, 1.2, 1.0, 2.0), Requirements(no_change_point=False))
    limit = math.degrees(math.acos(0.04))
    first, last = math.ceil(limit), math.floor(360 - limit)
    assert (first, last) == (88, 272)
    assert verdict.rule == "full_rotation"
    # the reason is the turning sentence: the limit angles (refined between the 1 deg steps) and Grashof
    assert verdict.reason.startswith(f"the input link '1' cannot turn fully: the mechanism assembles only for φ "
                                     f"from {360 - limit:.2f}° to {limit:.2f}° (through 0°), because the four-bar ")
    assert "is not a Grashof chain" in verdict.reason and "s + l = 3 m" in verdict.reason
    assert verdict.figures["unassembled_deg"] == [(first, last)]


def test_a_rocker_input_over_its_range_turns_within_it_and_is_singular_at_its_limit():
    limit = math.degrees(math.acos(0.04))            # the limit positions of the non-Grashof four-bar
    inside = four_bar(1.0, 1.2, 1.0, 2.0, header=f"range_deg = [{-(limit - 1)!r}, {limit - 1!r}]")
    verdict = check(inside)
    assert verdict.feasible
    np.testing.assert_allclose(np.degrees(sweep_angles(inside, 360)[[0, -1]]), [1 - limit, limit - 1])
    # up to 1e-7 deg from the limit, where coupler and rocker are nearly aligned (a dead point)
    edge = four_bar(1.0, 1.2, 1.0, 2.0, header=f"range_deg = [{-(limit - 1e-7)!r}, {limit - 1e-7!r}]")
    verdict = check(edge)
    assert verdict.rule == "non_singular"
    assert f"singular at phi = {-limit:.4g}, {limit:.4g} deg" in verdict.reason
    assert verdict.figures["min_transmission_angle_deg"] < 0.01
    assert check(edge, Requirements(non_singular=False)).feasible


PARALLELOGRAM = 'left_of = ["A", "C"]\nphi_deg = 90'


@pytest.mark.parametrize("mode", ["keep", "follow"])
def test_parallelogram_is_rejected_by_its_change_points_and_accepted_without_the_rule(mode):
    mech = four_bar(1.0, 2.0, 1.0, 2.0, f'{PARALLELOGRAM}\nmode = "{mode}"')
    verdict = check(mech)
    assert verdict.rule == "no_change_point"
    assert "group II-RRR(2,3) at phi = 0, 180 deg" in verdict.reason
    # the collinear positions of crank and ground, phi = 0 and 180 deg
    found = np.array(verdict.figures["change_points_deg"]["II-RRR(2,3)"])
    np.testing.assert_allclose(np.sort((found + 1.0) % 360.0 - 1.0), [0.0, 180.0], atol=1e-4)
    accepted = check(mech, Requirements(no_change_point=False))
    assert accepted.feasible                     # the singular positions at the change points are its own
    assert accepted.figures["min_transmission_angle_deg"] == pytest.approx(0.0, abs=1e-6)


def test_a_singular_position_between_the_angles_is_caught_by_its_branch_warning():
    # Whitworth quick return: O1 = (0, 0.05) inside the crank circle of radius 0.1, so the slotted
    # rocker turns fully; its slot O3 -> A lies parallel to the ram guide where A.y = 0:
    # sin(phi) = -0.5, phi = 210 and 330 deg. There the ram's PRP dyad cannot be assembled.
    text = scheme_path("slotted_link_two_dyad").read_text(encoding="utf-8")
    assert "O1 = [0.0, 0.12]" in text and "length = 0.076" in text
    mech = linkage.loads(text.replace("O1 = [0.0, 0.12]", "O1 = [0.0, 0.05]")
                         .replace("length = 0.076", "length = 0.1"))
    verdict = check(mech, Requirements(positions=360))
    assert verdict.rule == "full_rotation"
    assert "the mechanism assembles at every φ but 210° and 330°" in verdict.reason
    # 361 angles miss both: the PRP dyad flips assembly mode between two of them
    verdict = check(mech, Requirements(positions=361))
    assert verdict.rule == "no_change_point"
    assert "II-PRP(4,5)" in verdict.reason and verdict.figures["change_points_deg"] == {}


def test_nothing_leaks_to_the_warnings():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check(four_bar(1.0, 2.0, 1.0, 2.0, PARALLELOGRAM), Requirements(no_change_point=False))
        check(lambda: four_bar(0.1, 0.1, 0.1, 2.0))
    assert caught == []


# ----------------------------------------------------------------------------------------------
# assembles, stroke
# ----------------------------------------------------------------------------------------------


def test_a_variant_that_cannot_be_built_is_rejected_with_its_message():
    verdict = check(lambda: four_bar(0.1, 0.1, 0.1, 2.0))
    assert (verdict.feasible, verdict.rule) == (False, "assembles")
    assert "cannot be assembled at any input angle" in verdict.reason and "\n" not in verdict.reason

    def broken():
        return linkage.loads("name = 'x'\ninput = 1 2")

    assert check(broken).rule == "assembles"


def test_stroke_of_the_offset_slider_crank_and_its_bounds():
    r, rod, e = 0.1, 0.35, 0.03
    stroke = math.sqrt((rod + r) ** 2 - e**2) - math.sqrt((rod - r) ** 2 - e**2)
    mech = offset_slider_crank(r, rod, e)
    verdict = check(mech, Requirements(stroke=(stroke - 1e-6, stroke + 1e-6)))
    assert verdict.feasible                   # the extremes lie between the sweep's angles: refined
    assert verdict.figures["stroke"] == pytest.approx(stroke, abs=1e-8)
    assert verdict.figures["stroke_unit"] == "m"
    verdict = check(mech, Requirements(stroke=(0.1, 0.15)))
    assert verdict.rule == "stroke"
    assert verdict.reason == f"the stroke of B.x is {stroke:.6g} m, outside the required [0.1, 0.15] m"


def test_stroke_of_a_rocker_angle_from_its_extreme_positions():
    a, b, c, d = CRANK_ROCKER
    # extreme positions: crank and coupler aligned, |CB| seen from C at |OB| = b - a and b + a
    swing = [math.acos((c**2 + d**2 - ob**2) / (2 * c * d)) for ob in (b - a, b + a)]
    verdict = check(four_bar(a, b, c, d, header='output = "3.theta"'))
    assert verdict.figures["stroke"] == pytest.approx(swing[1] - swing[0], abs=1e-8)
    assert verdict.figures["stroke_unit"] == "rad"


def test_a_stroke_without_an_output_is_a_rejection():
    verdict = check(offset_slider_crank(0.1, 0.35, 0.0, output=False), Requirements(stroke=(0.1, 0.3)))
    assert verdict.rule == "stroke" and "declares no output" in verdict.reason
    assert verdict.figures["stroke"] is None


def test_the_first_failing_rule_wins():
    # non-Grashof and a stroke out of bounds: full rotation is checked first
    verdict = check(four_bar(1.0, 1.2, 1.0, 2.0, header='output = "3.theta"'), Requirements(stroke=(5, 6)))
    assert verdict.rule == "full_rotation"
    assert RULES.index("full_rotation") < RULES.index("stroke")
    assert isinstance(verdict, Verdict)


# ----------------------------------------------------------------------------------------------
# requirements from a TOML table
# ----------------------------------------------------------------------------------------------

WHERE = "press.toml [template.require]"


def test_parse_requirements_defaults_and_values():
    assert parse_requirements(None, WHERE) == Requirements()
    req = parse_requirements({"full_rotation": False, "min_transmission_angle_deg": 40, "stroke": [0.1, 0.2],
                              "positions": 720}, WHERE)
    assert req == Requirements(False, True, True, 40.0, (0.1, 0.2), 720)
    assert isinstance(req.min_transmission_angle_deg, float)


def test_parse_requirements_suggests_the_key_meant():
    with pytest.raises(SchemeError) as err:
        parse_requirements({"min_transmision_angle_deg": 40}, WHERE)
    message = str(err.value)
    assert message.startswith(WHERE)
    assert "unknown key 'min_transmision_angle_deg'; did you mean 'min_transmission_angle_deg'?" in message


@pytest.mark.parametrize("raw, words", [
    ({"full_rotation": "yes"}, "full_rotation must be true or false"),
    ({"min_transmission_angle_deg": 90}, "in (0, 90)"),
    ({"min_transmission_angle_deg": 0}, "in (0, 90)"),
    ({"min_transmission_angle_deg": "40"}, "in (0, 90)"),
    ({"stroke": [0.2, 0.1]}, "0 <= low < high"),
    ({"stroke": [-0.1, 0.1]}, "0 <= low < high"),
    ({"stroke": [0.1]}, "0 <= low < high"),
    ({"positions": 11}, "12..100000"),
    ({"positions": 100001}, "12..100000"),
    ({"positions": 360.0}, "an integer"),
    ({"positions": True}, "an integer"),
])
def test_parse_requirements_refuses_bad_values(raw, words):
    with pytest.raises(SchemeError) as err:
        parse_requirements(raw, WHERE)
    assert str(err.value).startswith(WHERE) and words in str(err.value)
    assert repr(next(iter(raw.values()))) in str(err.value)


def test_parse_requirements_lists_every_problem_at_once():
    with pytest.raises(SchemeError) as err:
        parse_requirements({"positions": 5, "stroke": [1, 0], "colour": "red"}, WHERE)
    assert len(err.value.problems) == 3 and all(p.startswith(WHERE) for p in err.value.problems)
    with pytest.raises(SchemeError, match=r"^press.toml \[template.require\]: expected a table"):
        parse_requirements([1, 2], WHERE)


def test_requirements_built_in_python_are_checked_too():
    with pytest.raises(InputError, match="positions"):
        Requirements(positions=3)
