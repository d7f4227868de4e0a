"""The [friction] section (linkage/kinetostatics/friction.py) as a scheme declares it, and the
command-line options that use it: `linkage forces --friction`, `linkage dynamics --friction`."""

from __future__ import annotations

import json

import numpy as np
import pytest

import linkage
from linkage.dynamics import course_method, run_dynamics
from linkage.errors import DynamicsInputError, InputError, SchemeError
from linkage.kinetostatics.friction import Friction, PairFriction, friction_of
from linkage.kinetostatics.reactions import solve_reactions
from linkage.model.scheme import shipped_schemes


def press(friction=None):
    mech = linkage.load("course_slider_crank")
    return mech if friction is None else mech.with_extra(friction=friction)


def test_the_course_press_declares_its_friction_and_each_pair_gets_its_values():
    friction = friction_of(press())
    assert friction.pairs == {
        "A": PairFriction("A", "R", 0.08, 0.03), "B": PairFriction("B", "R", 0.08, 0.03),
        "O": PairFriction("O", "R", 0.05, 0.04), "slide": PairFriction("slide", "P", 0.12, None, 0.12)}


def test_without_the_section_there_is_no_friction_and_solve_reactions_refuses_true():
    mech = linkage.load("four_bar")
    assert friction_of(mech) is None
    motion = linkage.analyze(mech, [0.3], omega=1.0, eps=0.0)
    with pytest.raises(InputError, match=r"declares no \[friction\]"):
        solve_reactions(motion, friction=True)


@pytest.mark.parametrize("section, words", [
    ({"revolute": {"f": -0.1, "radius": 0.02}}, "revolute: f must be a number in [0"),
    ({"revolute": {"f": float("nan"), "radius": 0.02}}, "got nan"),
    ({"revolute": {"f": 0.1, "radius": 0.0}}, "revolute: radius must be"),
    ({"revolute": {"f": 0.1}}, "revolute: needs radius = r (m, the journal's radius"),
    ({"prismatic": {"f": 0.1, "radius": 0.02}}, "prismatic: radius = 0.02: a radius belongs to a revolute pair"),
    ({"revolute": {"f": 0.1, "radius": 0.02, "length": 0.1}}, "revolute: length = 0.1: a length belongs to a prismatic"),
    ({"pairs": {"Z": {"f": 0.1}}}, "pairs.Z: mechanism 'course_slider_crank' has no pair 'Z' (its pairs: A, B, O, slide)"),
    ({"pairs": {"slide": {"f": 0.1, "radius": 0.01}}}, "pairs.slide: radius = 0.01: a radius belongs to a revolute"),
    ({"pairs": {"A": {"radius": 0.01}}}, "pairs.A: needs f"),
    ({"revolut": {"f": 0.1, "radius": 0.02}}, "did you mean 'revolute'"),
    ({"prismatic": 0.15}, "prismatic: expected a table like { f = 0.1 }"),
])
def test_a_wrong_section_is_refused_naming_the_key_and_the_value(section, words):
    with pytest.raises(SchemeError) as refused:
        friction_of(press(section))
    assert words in str(refused.value)
    assert str(refused.value).count("\n") == 0          # one message for one cause


def test_a_class_without_radius_is_one_message_for_every_revolute_pair():
    with pytest.raises(SchemeError) as refused:
        friction_of(press({"revolute": {"f": 0.1}}))
    assert "for the revolute pair(s) A, B, O" in str(refused.value)


def test_a_pair_s_own_values_override_its_class_and_f_zero_leaves_it_out():
    friction = friction_of(press({"revolute": {"f": 0.1, "radius": 0.02},
                                  "pairs": {"A": {"f": 0.0}, "B": {"radius": 0.05}}}))
    assert set(friction.pairs) == {"B", "O"}
    assert friction.pairs["B"] == PairFriction("B", "R", 0.1, 0.05)


def test_a_scheme_file_with_a_wrong_section_names_the_file(tmp_path):
    text = (linkage.model.scheme.scheme_path("course_slider_crank").read_text(encoding="utf-8")
            .replace("prismatic = { f = 0.12, length = 0.12 }", "prismatic = { f = 0.12, length = -1 }"))
    path = tmp_path / "press.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(SchemeError) as refused:
        linkage.load(path)
    assert str(path) in str(refused.value) and "prismatic: length must be" in str(refused.value)


def test_the_builder_takes_the_section_too():
    """A four-bar built in Python with friction: its balancing moment grows by the friction
    moments' virtual power (checked by the frictionless balance plus the losses)."""
    from linkage.model import MechanismBuilder
    b = MechanismBuilder("four_bar")
    b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "B"), length=0.3, mass=2.0, com="A")
    b.link("3", line=("C", "B"), length=0.25)
    for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        b.revolute(name, a, c)
    b.inputs("1").assembly("B", left_of=("A", "C"))
    mech = b.build(friction={"revolute": {"f": 0.1, "radius": 0.01}})
    assert set(friction_of(mech).pairs) == {"O", "A", "B", "C"}
    motion = linkage.analyze(mech, np.radians([20.0, 100.0, 250.0]), omega=5.0, eps=0.0)
    with_friction, plain = solve_reactions(motion, friction=True), solve_reactions(motion)
    lost = -with_friction.friction_power() / 5.0                 # N m per rad/s of crank speed
    assert np.all(lost > 0)
    # the frictionless loads' power is unchanged: M_b grows by exactly the friction's loss per unit speed
    np.testing.assert_allclose(with_friction.balancing_moment - plain.balancing_moment, lost, rtol=1e-9)
    with pytest.raises(SchemeError, match="pairs.Z"):
        friction_of(b.build(friction={"pairs": {"Z": {"f": 0.1}}}))


def test_friction_raises_the_driving_moment_and_the_flywheel_by_its_reduced_moment():
    """The friction's reduced moment (<= 0 everywhere: it always resists) is the difference of the
    resistances with and without it; the course's constant driving moment grows by its mean."""
    mech = press()
    plain = course_method(mech)
    report = run_dynamics(mech, friction=True, compare=False)
    law = report.law
    lost = law.reduced.moment_friction
    assert np.all(lost <= 1e-9)
    np.testing.assert_allclose(law.reduced.moment_resistance - lost, plain.reduced.moment_resistance,
                               rtol=1e-12, atol=1e-9)
    psi = np.abs(law.phi - law.phi[0])
    mean_loss = -np.trapezoid(lost, psi) / (2 * np.pi)
    assert law.driving_moment == pytest.approx(plain.driving_moment + mean_loss, rel=1e-9)
    assert law.flywheel_inertia > plain.flywheel_inertia
    summary = report.summary()
    assert summary["friction_work"] == pytest.approx(mean_loss * 2 * np.pi, rel=1e-9)
    assert summary["cycle_efficiency"] == pytest.approx(1 - mean_loss / law.driving_moment, rel=1e-9)


def test_dynamics_without_the_section_refuses_friction():
    with pytest.raises(DynamicsInputError, match=r"declares no \[friction\]"):
        run_dynamics(linkage.load("flying_shears"), friction=True)


def test_forces_friction_on_the_command_line(linkage_run):
    run = linkage_run("forces", "course_slider_crank", "--friction", "--format", "json")
    assert run.status == 0, run.err
    doc = json.loads(run.out)
    meta, rows = doc, doc["rows"]
    assert meta["friction"]["slide"] == {"kind": "P", "f": 0.12, "length": 0.12}
    cycle = meta["cycle"]
    assert cycle["driving_work"] == pytest.approx(cycle["useful_work"] + cycle["friction_work"], rel=1e-9)
    assert 0 < cycle["efficiency"] < 1
    assert doc["units"]["slide.Ff"] == "N" and doc["units"]["A.Mf"] == "N m" and doc["units"]["power_lost"] == "W"
    for row in rows:
        pairs = [row[f"{k}.power_lost"] for k in ("A", "B", "O", "slide")]
        assert row["power_lost"] == pytest.approx(sum(pairs), rel=1e-12)
        # a revolute pair's loss is its friction moment times the relative speed of its links
        assert row["A.power_lost"] >= 0 and abs(row["A.Mf"]) == pytest.approx(0.08 * 0.03 * row["A.R"], rel=1e-12)
    plain = json.loads(linkage_run("forces", "course_slider_crank", "--format", "json").out)["rows"]
    # clockwise drive: with friction the balancing moment is more negative wherever the drive works
    worse = [r["balancing_moment"] < p["balancing_moment"] for r, p in zip(rows, plain)]
    assert sum(worse) >= len(rows) - 1


def test_forces_friction_table_shows_the_losses(linkage_run):
    run = linkage_run("forces", "course_slider_crank", "--friction")
    assert run.status == 0, run.err
    assert "efficiency" in run.out and "power_lost" in run.out and "# cycle: one turn" in run.out


def test_forces_friction_without_the_section_is_one_line(linkage_run):
    run = linkage_run("forces", "four_bar", "--friction")
    assert run.status == 2
    assert run.err.strip().count("\n") == 0 and "declares no [friction]" in run.err


def test_dynamics_friction_on_the_command_line(linkage_run):
    run = linkage_run("dynamics", "course_slider_crank", "--friction", "--format", "json")
    assert run.status == 0, run.err
    doc = json.loads(run.out)
    assert "reduced_moment_friction" in doc["rows"][0]
    assert doc["friction_work"] > 0 and 0 < doc["cycle_efficiency"] < 1


def test_no_shipped_scheme_but_the_press_declares_friction():
    declared = [name for name in shipped_schemes() if friction_of(linkage.load(name)) is not None]
    assert declared == ["course_slider_crank"]


def test_friction_with_f_zero_in_every_pair_is_frictionless():
    mech = press()
    motion = linkage.analyze(mech, np.radians(np.arange(0, 360, 45)), omega=-10.0, eps=2.0)
    none = Friction({})
    a, b = solve_reactions(motion), solve_reactions(motion, friction=none)
    np.testing.assert_array_equal(a.balancing_moment, b.balancing_moment)


@pytest.mark.parametrize("method", ["course", "exact"])
def test_friction_under_the_law_of_motion_is_that_of_its_own_speeds(method):
    """With real_speed the friction's reduced moment at the table positions is the one the
    kinetostatics gives under the final law's omega(phi) and eps(phi) (computed here directly),
    to the settling tolerance; it differs from the mean-speed one by the inertia loads' share."""
    mech = press()
    report = run_dynamics(mech, method, friction=True, real_speed=True, compare=False)
    law = report.law
    assert any("settled in" in n for n in report.notes)
    motion = linkage.analyze(mech, law.phi, order=2, omega=law.omega, eps=law.eps)
    ends = np.arange(len(law.phi)) == len(law.phi) - 1        # the last position ends the cycle
    reactions = solve_reactions(motion, ends=ends, friction=True, sense=law.reduced.rotation)
    direct = law.reduced.rotation * reactions.friction_power() / motion.omega
    scale = np.max(np.abs(direct))
    # the last position repeats the first (its speed taken as the first's: the law is periodic)
    np.testing.assert_allclose(law.reduced.moment_friction[:-1], direct[:-1], atol=1e-5 * scale)
    at_mean = run_dynamics(mech, method, friction=True, compare=False).law.reduced.moment_friction
    assert np.max(np.abs(at_mean - direct)) > 1e-4 * scale


def test_real_speed_needs_friction(linkage_run):
    run = linkage_run("dynamics", "course_slider_crank", "--friction-real-speed")
    assert run.status == 2 and "give --friction with it" in run.err
