"""Change points: where a group's two assembly modes meet, the user chooses how it goes on.

Oracles are the textbook closed forms of the parallelogram, the deltoid (kite) and the isosceles
slider-crank in each assembly mode, written here independently of the solvers.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import linkage
from linkage.kinematics.assembly import assembly_plans
from linkage.kinematics.motion import BranchWarning

from _texts import four_bar_toml, slider_crank_toml


def four_bar(crank, coupler, rocker, ground, condition, mode="keep"):
    return four_bar_toml(crank, coupler, rocker, ground, f'{condition}\nmode = "{mode}"',
                         name=f"four_bar_{crank}_{coupler}_{rocker}_{ground}")


def isosceles(mode=None, condition='from = "O"\ntowards_deg = 0\nphi_deg = 45'):
    """Slider-crank with rod = crank = 1: at +-90 deg the slider may follow the crank or rest at O."""
    return slider_crank_toml(1.0, 1.0, condition + (f'\nmode = "{mode}"' if mode else ""),
                             name="isosceles_slider_crank")


TURN = np.radians(np.arange(2.5, 360.0, 5.0))          # a table over one turn, off the change points


def _analyze(mech, phi):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = linkage.analyze(mech, phi, on_failure="mask")
    return motion, [str(w.message) for w in caught if issubclass(w.category, BranchWarning)]


PARALLELOGRAM = 'left_of = ["A", "C"]\nphi_deg = 90'


def test_parallelogram_change_points_are_found_at_the_collinear_positions():
    plan = assembly_plans(linkage.loads(four_bar(1, 2, 1, 2, PARALLELOGRAM)))[0]
    np.testing.assert_allclose(np.sort(plan.change_points), [np.pi, 2 * np.pi], atol=1e-6)


def test_parallelogram_followed_stays_a_parallelogram_over_the_whole_turn():
    mech = linkage.loads(four_bar(1, 2, 1, 2, PARALLELOGRAM, "follow"))
    for phi in (TURN, np.linspace(0.0, 4 * np.pi, 2001)[1:-1]):
        motion, caught = _analyze(mech, phi)
        ok = motion.status == 0
        assert ok.mean() > 0.99
        assert caught == []
        # the coupler translates: B - A = (2, 0); the rocker stays parallel to the crank
        np.testing.assert_allclose((motion.point("B") - motion.point("A"))[ok], [[2.0, 0.0]] * ok.sum(),
                                   atol=1e-9)
        np.testing.assert_allclose(motion.quantity("3.theta")[1][ok], 1.0, atol=1e-8)


def test_parallelogram_kept_switches_to_the_antiparallelogram_with_a_warning():
    mech = linkage.loads(four_bar(1, 2, 1, 2, PARALLELOGRAM))
    motion, caught = _analyze(mech, TURN)
    assert len(caught) == 1 and "II-RRR(2,3)" in caught[0] and "180" in caught[0] and "follow" in caught[0]
    coupler = motion.point("B") - motion.point("A")
    first_half = TURN < np.pi
    np.testing.assert_allclose(coupler[first_half], [[2.0, 0.0]] * first_half.sum(), atol=1e-9)
    assert np.all(np.abs(coupler[~first_half][:, 1]) > 1e-3)          # crossed: not a parallelogram


def test_antiparallelogram_followed_over_the_whole_turn():
    mech = linkage.loads(four_bar(1, 2, 1, 2, 'right_of = ["A", "C"]\nphi_deg = 90', "follow"))
    motion, caught = _analyze(mech, TURN)
    assert caught == []
    coupler = motion.point("B") - motion.point("A")
    assert np.all(np.abs(coupler[:, 1]) > 1e-3)
    # the crossed four-bar O-A-B-C is an isosceles trapezoid O-A-C-B whose legs are the crank
    # and the rocker: its parallel sides OB and AC stay parallel over the whole turn
    B, A, C = motion.point("B"), motion.point("A"), np.array([2.0, 0.0])
    np.testing.assert_allclose(B[:, 0] * (C - A)[:, 1] - B[:, 1] * (C - A)[:, 0], 0.0, atol=1e-9)


def _kite(phi, far):
    """The deltoid (OA = OC = 1, AB = CB = 2) is symmetric about OB: B = rho (cos psi, sin psi)."""
    half = phi / 2
    if far:
        psi, rho = half, np.cos(half) + np.sqrt(np.cos(half) ** 2 + 3)
    else:
        psi, rho = half + np.pi, -np.cos(half) + np.sqrt(np.cos(half) ** 2 + 3)
    return np.column_stack([rho * np.cos(psi), rho * np.sin(psi)])


@pytest.mark.parametrize("towards, far", [(180, False), (0, True)])
def test_deltoid_followed_through_its_change_point(towards, far):
    condition = f'from = "O"\ntowards_deg = {towards}\nphi_deg = 1'
    mech = linkage.loads(four_bar(1, 2, 2, 1, condition, "follow"))
    phi = np.radians(np.arange(-177.5, 180.0, 5.0))
    motion, caught = _analyze(mech, phi)
    assert caught == []
    np.testing.assert_allclose(motion.point("B"), _kite(phi, far), atol=1e-9)


def test_deltoid_kept_jumps_with_a_warning_naming_the_group_and_the_angle():
    mech = linkage.loads(four_bar(1, 2, 2, 1, 'left_of = ["A", "C"]'))
    phi = np.radians([-0.01, 0.01])
    motion, caught = _analyze(mech, phi)
    assert np.linalg.norm(motion.point("B")[1] - motion.point("B")[0]) > 3.9     # the 4 m jump
    assert len(caught) == 1 and "II-RRR(2,3)" in caught[0] and "angle(s) 0 deg" in caught[0]


def test_deltoid_followed_over_a_whole_turn_says_it_repeats_after_two_turns():
    mech = linkage.loads(four_bar(1, 2, 2, 1, 'from = "O"\ntowards_deg = 180\nphi_deg = 1', "follow"))
    _, caught = _analyze(mech, np.linspace(-np.pi, np.pi, 73))
    assert len(caught) == 1 and "two turns" in caught[0]


def test_isosceles_slider_crank_followed_keeps_following_the_crank():
    mech = linkage.loads(isosceles("follow"))
    motion, caught = _analyze(mech, TURN)
    assert caught == []
    np.testing.assert_allclose(motion.point("B")[:, 0], 2 * np.cos(TURN), atol=1e-9)
    np.testing.assert_allclose(motion.quantity("B.x")[1], -2 * np.sin(TURN), atol=1e-8)


def test_isosceles_slider_crank_kept_rests_at_the_pivot_half_the_turn_with_a_warning():
    mech = linkage.loads(isosceles("keep"))
    motion, caught = _analyze(mech, TURN)
    assert len(caught) == 1 and "90" in caught[0] and "270" in caught[0]
    right = np.cos(TURN) > 0
    np.testing.assert_allclose(motion.point("B")[right, 0], 2 * np.cos(TURN[right]), atol=1e-9)
    np.testing.assert_allclose(motion.point("B")[~right, 0], 0.0, atol=1e-9)


def _parallelogram_builder():
    b = linkage.MechanismBuilder("p")
    b.link("0", points={"O": (0.0, 0.0), "C": (2.0, 0.0)})
    b.link("1", line=("O", "A"), length=1.0)
    b.link("2", line=("A", "B"), length=2.0)
    b.link("3", line=("C", "B"), length=1.0)
    for name, x, y in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, x, y)
    return b


def test_mode_and_angle_round_trip_through_scheme_files_and_the_builder():
    mech = linkage.loads(four_bar(1, 2, 1, 2, PARALLELOGRAM, "follow"))
    rule = mech.assembly[0]
    assert (rule.mode, rule.phi) == ("follow", pytest.approx(np.pi / 2))
    assert linkage.loads(linkage.dumps(mech)) == mech
    b = _parallelogram_builder()
    b.inputs("1").assembly("B", left_of=("A", "C"), phi=np.pi / 2, mode="follow")
    built = b.build()
    assert assembly_plans(built)[0].mode == "follow"
    motion, _ = _analyze(built, TURN)
    np.testing.assert_allclose((motion.point("B") - motion.point("A"))[motion.status == 0][:, 0], 2.0,
                               atol=1e-9)


@pytest.mark.parametrize("mode, phi, message", [
    ("sideways", None, "mode must be 'keep' or 'follow', got 'sideways'"),
    ("keep", float("nan"), "input angle of the condition must be a finite number"),
])
def test_bad_mode_or_angle_is_refused(mode, phi, message):
    b = _parallelogram_builder()
    b.inputs("1").assembly("B", left_of=("A", "C"), phi=phi, mode=mode)
    with pytest.raises(linkage.SchemeError, match=message):
        b.build()


def test_a_four_bar_that_never_assembles_names_the_group_and_the_dimensions():
    with pytest.raises(linkage.SchemeError) as info:
        linkage.loads(four_bar(1, 1, 1, 5, 'left_of = ["A", "C"]'), source="far.toml")
    message = str(info.value)
    assert message.count("\n") == 0
    assert "far.toml" in message and "II-RRR(2,3) cannot be assembled at any input angle" in message
    assert "|AC| >= 4 m at every angle but AB + CB = 2 m" in message


def test_a_condition_that_holds_on_neither_candidate_at_its_angle_is_refused():
    with pytest.raises(linkage.SchemeError, match="does not tell the two branches"):
        linkage.loads(four_bar(1, 2, 1, 2, 'left_of = ["A", "C"]\nphi_deg = 0'))


def test_a_jump_the_change_point_search_missed_is_still_reported():
    """Safety net: with the change point hidden from the plan, the deltoid's 4 m jump between two
    analysed angles 1 deg apart is reported by comparing the motion with its analogs."""
    from linkage.kinematics.assembly import BranchPlan

    mech = linkage.loads(four_bar(1, 2, 2, 1, 'left_of = ["A", "C"]'))
    mech.cache["plans"] = (BranchPlan(1, "keep", np.empty(0), np.empty(0, bool)),)
    _, caught = _analyze(mech, np.radians([-1.5, -0.5, 0.5, 1.5]))
    assert len(caught) == 1 and "-0.5..0.5" in caught[0] and "II-RRR(2,3)" in caught[0]
    # and a smooth motion sampled just as finely, or coarsely, raises nothing
    _, caught = _analyze(linkage.load("four_bar"), np.radians(np.arange(0.0, 360.0, 10.0)))
    assert caught == []


@pytest.mark.parametrize("entry, message", [
    ('left_of = ["A", "C"]\nfrom_ = "O"', "assembly.B: unknown keys \\['from_'\\]"),
    ('left_of = ["A", "C"]\nphi_deg = 1e300', "assembly.B: 'phi_deg' must be a number with \\|x\\| <= 1e\\+06 deg, got 1e\\+300"),
    ('from = "O"\ntowards_deg = "up"', "assembly.B: 'towards_deg' must be a number with"),
])
def test_bad_assembly_entries_give_one_message_naming_the_entry(entry, message):
    with pytest.raises(linkage.SchemeError, match=message) as info:
        linkage.loads(four_bar(1, 2, 1, 2, entry).replace('mode = "keep"\n', ""), source="bad.toml")
    assert len(info.value.problems) == 1 and info.value.problems[0].startswith("bad.toml: ")


def test_conditions_are_judged_over_the_declared_input_range():
    """Followed over a turn, 'B left of A -> C' holds for the parallelogram half the time and for
    its crossed twin the other half (a tie, refused); over the range 10..170 deg it tells them
    apart."""
    text = four_bar(1, 2, 1, 2, 'left_of = ["A", "C"]', "follow")
    with pytest.raises(linkage.SchemeError, match="does not tell the two branches"):
        linkage.loads(text)
    ranged = linkage.loads('range_deg = [10.0, 170.0]\n' + text)
    phi = np.radians(np.linspace(10.0, 170.0, 17))
    motion, caught = _analyze(ranged, phi)
    assert caught == []
    np.testing.assert_allclose(motion.point("B") - motion.point("A"), [[2.0, 0.0]] * len(phi), atol=1e-9)


def test_a_towards_condition_that_neither_branch_meets_names_its_angle():
    text = isosceles(condition='from = "O"\ntowards_deg = 90')
    with pytest.raises(linkage.SchemeError, match="from 'O' towards 90 deg"):
        linkage.loads(text)
