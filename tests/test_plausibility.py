"""Plausibility notes (issue 21, item 5: "mistakes nobody can see").

A scheme that is valid but almost never meant -- lengths typed in mm, masses out of scale with
the lengths, gravity pointing up, radians typed into ``*_deg`` keys, a speed over 10000 rpm --
loads with one :class:`linkage.PlausibilityWarning` naming the file and the key, silenced by
``[checks] silence = [...]`` or by Python's warning filters; every shipped scheme and template
stays silent. The reproducers are the shipped ``four_bar`` (O = (0, 0), C = (0.3, 0), OA = 0.1,
AB = 0.3, CB = 0.25 m; masses 1 + 3 + 2 = 6 kg) with one value changed, so each expected figure
is computed here from those declared numbers.
"""

from __future__ import annotations

import itertools
import math
import re
import warnings
from pathlib import Path

import pytest

import linkage
from linkage import PlausibilityWarning, SchemeError
from linkage.course.template import draws, load_template, loads_template, shipped_templates
from linkage.course.variants import select_variants
from linkage.model.scheme import scheme_path, toml_text

FOUR_BAR = scheme_path("four_bar").read_text(encoding="utf-8")
FOUR_BAR_MASS = 1.0 + 3.0 + 2.0  # kg, links 1, 2, 3 as declared


def scaled_four_bar(k: float) -> str:
    """four_bar with every length and coordinate times ``k`` (the masses kept in kg)."""
    text = FOUR_BAR
    for old in ("0.3", "0.1", "0.25", "0.15", "0.125"):  # each appears as a whole number token
        text = re.sub(rf"(?<![\d.]){re.escape(old)}(?![\d])", f"{float(old) * k:g}", text)
    return text


def loaded(text: str, source: str = "mistake.toml") -> tuple[linkage.Mechanism, list[str]]:
    """The mechanism of ``text`` and the messages of the PlausibilityWarnings its loading gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = linkage.loads(text, source=source)
    return mech, [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]


GRAVITY_NOTE = ("points up: y is up, so gravity down is [0, -9.81] (the default); was the sign of its y left out? "
                '(if meant, silence this note with [checks] silence = ["gravity"] in the scheme)')


def with_dynamics(text: str, lines: str) -> str:
    return text + "\n[dynamics]\n" + lines + "\n"


# ----------------------------------------------------------------------------------------------
# each note on its reproducer, naming the file and the key
# ----------------------------------------------------------------------------------------------


def test_the_reproducer_is_four_bar_scaled():
    mech, _ = loaded(scaled_four_bar(1000.0))
    base = linkage.load("four_bar")
    assert mech.size == pytest.approx(1000.0 * base.size)
    assert mech.links["1"].points["A"] == pytest.approx((100.0, 0.0))
    assert mech.links["2"].points["E"] == pytest.approx(tuple(1000.0 * v for v in base.links["2"].points["E"]))


def test_lengths_in_mm_give_one_note_naming_each_long_link():
    _, messages = loaded(scaled_four_bar(1000.0), "crank_mm.toml")
    assert len(messages) == 1, messages  # the masses are out of scale for the same cause: not said twice
    text = messages[0]
    assert text.startswith("crank_mm.toml: ")
    # the largest distance between two points of each link: O-C 300, OA 100, AB 300 (E lies
    # within it), CB 250 m
    for key, size in (("links.0.points", 300), ("links.1.length", 100), ("links.2.length", 300),
                      ("links.3.length", 250)):
        assert f"{key} ({size:g} m)" in text
    assert "over 50 m" in text and "lengths are in m" in text
    assert '[checks] silence = ["lengths"]' in text


def test_a_link_of_50_m_is_meant_and_one_just_over_is_not():
    _, quiet = loaded(scaled_four_bar(50.0 / 0.3))     # the longest link exactly 50 m
    assert not [m for m in quiet if "over 50 m long" in m]
    _, noisy = loaded(scaled_four_bar(50.001 / 0.3))
    assert any("links.0.points (50.001 m)" in m for m in noisy)


def test_masses_out_of_scale_with_lengths_in_cm():
    """Typed in cm the longest link is 30 m (no length note), but 6 kg in a 30 m mechanism is
    6 / 30^3 = 2.2e-4 kg/m^3 of mass per size cubed, below 1e-3."""
    _, messages = loaded(scaled_four_bar(100.0), "crank_cm.toml")
    assert len(messages) == 1, messages
    text = messages[0]
    density = FOUR_BAR_MASS / 30.0**3
    assert text.startswith("crank_cm.toml: links.1.mass, links.2.mass, links.3.mass: ")
    assert f"total {FOUR_BAR_MASS:g} kg" in text and "(30 m" in text
    assert f"{density:.3g} kg/m^3" in text and "a length typed in mm" in text
    assert '[checks] silence = ["masses"]' in text


def test_masses_in_grams_out_of_scale_the_other_way():
    text = FOUR_BAR.replace("mass = 3.0", "mass = 3e6")      # link 2 in g, times 1000 again
    _, messages = loaded(text)
    density = (1.0 + 3e6 + 2.0) / 0.3**3
    assert len(messages) == 1 and f"{density:.3g} kg/m^3" in messages[0] and "a mass typed in g" in messages[0]


def test_the_masses_note_follows_when_the_lengths_are_silenced():
    text = scaled_four_bar(1000.0) + '\n[checks]\nsilence = ["lengths"]\n'
    _, messages = loaded(text)
    assert len(messages) == 1 and f"{FOUR_BAR_MASS / 300.0**3:.3g} kg/m^3" in messages[0]


@pytest.mark.parametrize("gravity, noted", [((0.0, 9.81), True), ((1.0, 0.5), True), ((0.0, -9.81), False),
                                            ((9.81, 0.0), False), ((0.0, 0.0), False)])
def test_gravity_pointing_up(gravity, noted):
    text = FOUR_BAR.replace("gravity = [0.0, -9.81]", f"gravity = [{gravity[0]!r}, {gravity[1]!r}]")
    assert text != FOUR_BAR or gravity == (0.0, -9.81)
    _, messages = loaded(text, "up.toml")
    if noted:
        assert messages == [f"up.toml: loads.gravity = [{gravity[0]:g}, {gravity[1]:g}] m/s^2 {GRAVITY_NOTE}"]
    else:
        assert messages == []


def degrees_four_bar(angle: float, start: float) -> str:
    """four_bar with the coupler point E at ``angle_deg = angle`` and ``[dynamics] start_deg = start``."""
    text = FOUR_BAR.replace("distance = 0.15, angle_deg = 30", f"distance = 0.15, angle_deg = {angle!r}")
    return with_dynamics(text, f"mean_rpm = 60\nstart_deg = {start!r}")


def test_radians_typed_into_degree_keys():
    _, messages = loaded(degrees_four_bar(math.pi / 6, math.pi / 2), "rad.toml")
    assert len(messages) == 1, messages
    text = messages[0]
    assert text.startswith(f"rad.toml: links.2.points.E.angle_deg = {math.pi / 6:g}, dynamics.start_deg = "
                           f"{math.pi / 2:g}: ")
    assert f"({math.pi / 2:g} rad would be 90 deg)" in text
    assert '[checks] silence = ["degrees"]' in text


@pytest.mark.parametrize("angle, start", [(3, 0), (3.0, 0.0), (3, 5), (30, 1.5), (0.5, 0), (0, 0)])
def test_degrees_that_look_like_degrees_are_not_noted(angle, start):
    """One small angle (3 deg), whole small angles, or one value beyond 2 pi: degrees."""
    _, messages = loaded(degrees_four_bar(angle, start))
    assert messages == []


@pytest.mark.parametrize("line, key, rpm", [("mean_rpm = 12000", "dynamics.mean_rpm", 12000.0),
                                            ("mean_rpm = -10001", "dynamics.mean_rpm", 10001.0),
                                            ("mean_speed = 1440", "dynamics.mean_speed", 1440 * 60 / (2 * math.pi))])
def test_a_speed_over_10000_rpm(line, key, rpm):
    _, messages = loaded(with_dynamics(FOUR_BAR, line), "fast.toml")
    assert len(messages) == 1, messages
    assert messages[0].startswith(f"fast.toml: {key} = {line.split('= ')[1]}: {rpm:.6g} rpm ")
    assert "over 10000 rpm" in messages[0] and '[checks] silence = ["speed"]' in messages[0]
    if key.endswith("mean_speed"):
        assert "(mean_rpm)" in messages[0]


def test_a_motor_speed_over_10000_rpm():
    motor = ('motor = { kind = "induction", rated_moment = 10.0, synchronous_rpm = 15000, rated_rpm = 14400, '
             'overload = 2.0, ratio = 100.0 }')
    _, messages = loaded(with_dynamics(FOUR_BAR, f"mean_rpm = -144\ndelta = 0.05\n{motor}"))
    assert [m.split(":")[1].strip() for m in messages] == ["dynamics.motor.synchronous_rpm = 15000",
                                                           "dynamics.motor.rated_rpm = 14400"]


def test_10000_rpm_is_meant():
    _, messages = loaded(with_dynamics(FOUR_BAR, "mean_rpm = -10000"))
    assert messages == []


# ----------------------------------------------------------------------------------------------
# silencing
# ----------------------------------------------------------------------------------------------

REPRODUCERS = {
    "lengths": scaled_four_bar(1000.0),
    "masses": scaled_four_bar(100.0),
    "gravity": FOUR_BAR.replace("gravity = [0.0, -9.81]", "gravity = [0.0, 9.81]"),
    "degrees": degrees_four_bar(math.pi / 6, math.pi / 2),
    "speed": with_dynamics(FOUR_BAR, "mean_rpm = 12000"),
}


@pytest.mark.parametrize("check", list(REPRODUCERS))
def test_each_note_is_silenced_by_its_name(check):
    _, before = loaded(REPRODUCERS[check])
    assert len(before) == 1 and f'silence = ["{check}"]' in before[0]
    mech, after = loaded(REPRODUCERS[check] + f'\n[checks]\nsilence = ["{check}"]\n')
    assert not [m for m in after if f'silence = ["{check}"]' in m]
    # silenced lengths leave the masses' note, which they hid (the test above); nothing else is said
    assert len(after) == (1 if check == "lengths" else 0)
    again, _ = loaded(linkage.dumps(mech))            # the silence is written back and read again
    assert again == mech and again.parts["checks"] == frozenset({check})


def test_silencing_another_check_leaves_the_note():
    _, messages = loaded(REPRODUCERS["gravity"] + '\n[checks]\nsilence = ["lengths", "speed"]\n')
    assert len(messages) == 1 and "loads.gravity" in messages[0]


def test_python_filters_silence_every_note():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.filterwarnings("ignore", category=linkage.PlausibilityWarning)
        for text in REPRODUCERS.values():
            linkage.loads(text)
    assert not [w for w in caught if issubclass(w.category, PlausibilityWarning)]
    assert issubclass(PlausibilityWarning, UserWarning)


@pytest.mark.parametrize("checks, problem", [
    ('silence = ["gravty"]', "bad.toml: checks: silence: unknown check 'gravty'; did you mean 'gravity'?"),
    ('silense = ["gravity"]', "bad.toml: checks: unknown key 'silense'; did you mean 'silence'?"),
    ('silence = "gravity"', "bad.toml: checks: silence: expected a list of check names"),
    ("silence = [1]", "bad.toml: checks: silence: expected a list of check names"),
])
def test_a_wrong_silence_is_an_error_naming_the_key(checks, problem):
    with pytest.raises(SchemeError) as err:
        linkage.loads(FOUR_BAR + f"\n[checks]\n{checks}\n", source="bad.toml")
    assert len(err.value.problems) == 1 and err.value.problems[0].startswith(problem), err.value.problems


# ----------------------------------------------------------------------------------------------
# once per check and key in a warnings context; the shipped schemes and templates are silent
# ----------------------------------------------------------------------------------------------


def test_a_note_is_given_once_per_warnings_context():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k in (1000.0, 2000.0, 3000.0):           # three variants of the same mistake
            linkage.loads(scaled_four_bar(k), source="draw.toml")
    assert len([w for w in caught if issubclass(w.category, PlausibilityWarning)]) == 1
    _, again = loaded(scaled_four_bar(1000.0))        # a new context says it again
    assert len(again) == 1


@pytest.mark.parametrize("name", list(linkage.shipped_schemes()))
def test_every_shipped_scheme_is_silent(name):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        linkage.load(name)
    assert not [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]


@pytest.mark.parametrize("name", list(shipped_templates()))
def test_every_shipped_template_is_silent(name):
    """Variants drawn from the template, each loaded as the scheme file `linkage variants` writes."""
    template = load_template(name)
    said = []
    for i, free in enumerate(itertools.islice(draws(template, 7), 12)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                linkage.loads(toml_text(template.scheme_data(free, f"{name}_{i}")), source=f"variant {i}")
            except linkage.LinkageError:
                continue                               # an infeasible draw: not what is checked here
        said += [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]
    assert said == []


def test_a_template_s_variants_say_a_note_once():
    """press_slider_crank with gravity pointing up: drawing its variants and loading each as the
    scheme file `linkage variants` writes gives the note once."""
    path = shipped_templates()["press_slider_crank"]
    text = path.read_text(encoding="utf-8").replace("gravity = [0.0, -9.81]", "gravity = [0.0, 9.81]")
    template = loads_template(text, source="up_template.toml")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        selection = select_variants(template, 3, seed=5)
        for v in selection.variants:
            linkage.loads(toml_text(template.scheme_data(v.free, f"press_{v.label}")), source=f"variant {v.label}")
    messages = [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]
    assert len(selection.variants) == 3
    # the draws are loaded inside the feasibility check, which keeps its warnings; the first
    # variant built says the note, the others do not
    first = selection.variants[0].label
    assert len(messages) == 1 and messages[0].startswith(f"variant {first}: loads.gravity = [0, 9.81]"), messages


# ----------------------------------------------------------------------------------------------
# the command line
# ----------------------------------------------------------------------------------------------


def warning_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("linkage: warning:")]


def test_the_command_line_says_one_warning_and_goes_on(tmp_path, linkage_run):
    scheme = tmp_path / "up.toml"
    scheme.write_text(REPRODUCERS["gravity"], encoding="utf-8")
    run = linkage_run("forces", str(scheme), "--positions", "4", "--format", "csv")
    assert run.status == 0, run.err
    assert warning_lines(run.err) == [f"linkage: warning: {scheme}: loads.gravity = [0, 9.81] m/s^2 {GRAVITY_NOTE}"]
    assert run.out.startswith("i,phi_deg,balancing_moment,")  # the table follows the note


def test_the_command_line_notes_a_fast_rpm_once(linkage_run):
    run = linkage_run("forces", "four_bar", "--positions", "4", "--rpm", "12000", "--format", "csv")
    assert run.status == 0, run.err
    said = (f"--rpm 12000: 12000 rpm ({12000 * 2 * math.pi / 60:.6g} rad/s) is over 10000 rpm: rpm keys are in "
            'rpm, speed keys and --omega in rad/s; silence this note with [checks] silence = ["speed"] in the scheme')
    assert warning_lines(run.err) == [f"linkage: warning: {said}"]


def test_the_command_line_speed_note_is_silenced_by_the_scheme(tmp_path, linkage_run):
    scheme = tmp_path / "fast_meant.toml"
    scheme.write_text(FOUR_BAR + '\n[checks]\nsilence = ["speed"]\n', encoding="utf-8")
    run = linkage_run("forces", str(scheme), "--positions", "4", "--omega", "2000", "--format", "csv")
    assert run.status == 0 and warning_lines(run.err) == [], run.err
    loud = linkage_run("forces", "four_bar", "--positions", "4", "--omega", "2000", "--format", "csv")
    assert [line.split(":")[2].strip() for line in warning_lines(loud.err)] == ["--omega 2000"]


def test_the_docs_name_every_check():
    readme = (Path(linkage.__file__).resolve().parents[1] / "schemes" / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Plausibility notes")[1].split("\n## ")[0]
    from linkage.model.plausibility import CHECKS
    assert all(f"| `{name}` |" in section for name in CHECKS)
