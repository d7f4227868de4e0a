"""Validation that finds the root cause (issue 7, build 4; "What was seen" 6 and 7).

Every case is a small edit of a shipped scheme written under a distinctive file name, loaded
with :func:`linkage.load` or run through the command line (:func:`linkage.cli.main`), and must
give one :class:`linkage.SchemeError` (exit status 2 on the command line, no traceback) whose
message names the file, the entry and the value -- before any number is computed from it:

- ranges: every number finite and within its documented range (``schemes/README.md``, "Checks
  and ranges"), so that no computation overflows (``length = 1e200`` used to raise a raw
  OverflowError in the RRR / RRP solvers, ``mean_speed = -1e200`` one in the course method,
  ``delta = 5e-324``, ``inertia = 1e308`` and ``overload = 1e200`` raw SciPy errors with
  ``--method ode``);
- structure first, one message per root cause (a misspelt ``link`` in a ``[pairs.X]`` of a
  scheme with ``[loads]`` was reported as "mobility W = 3" without the file name);
- parse once: the loads and dynamics inputs are parsed when the scheme is loaded and kept, and
  the reactions neither re-parse them nor re-run kinematics for the stroke ends;
- every error the library raises on purpose is a :class:`linkage.LinkageError`.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import linkage
from _cli_io import run
from linkage import InputError, LinkageError, SchemeError
from linkage.dynamics.spec import dynamics_of
from linkage.kinetostatics.loads import StrokeDiagram, evaluate_loads, inertia_terms, loads_of
from linkage.kinetostatics.reactions import solve_reactions
from linkage.model.scheme import SECTION_PARSERS, from_dict, to_dict

SCHEMES = linkage.shipped_schemes()


def text_of(name: str) -> str:
    return SCHEMES[name].read_text(encoding="utf-8")


def edit(text: str, old: str, new: str) -> str:
    """``text`` with the one occurrence of ``old`` replaced (fails loudly on a stale edit)."""
    assert text.count(old) == 1, f"edit target {old!r} occurs {text.count(old)} times"
    return text.replace(old, new)


def names(path, *parts: str) -> str:
    """Regex: a line of the message that starts with the file and contains ``parts`` in order."""
    return "(?m)^" + re.escape(str(path)) + ".*" + ".*".join(re.escape(p) for p in parts)


def file_name(case: str) -> str:
    """A distinctive file name for a case ("length 1e200" -> "length_1e200.toml")."""
    return re.sub(r"\W+", "_", case) + ".toml"


def write(tmp_path: Path, file: str, text: str) -> Path:
    path = tmp_path / file
    path.write_text(text, encoding="utf-8")
    return path


# ----------------------------------------------------------------------------------------------
# ranges: (scheme, old text, new text, parts the message names in order)
# ----------------------------------------------------------------------------------------------

RANGE_CASES = {
    # the cases of the issue
    "length 1e200": ("course_slider_crank", "length = 0.0742", "length = 1e200",
                     ("link '1'", "length", "1e+200")),
    "mean_speed -1e200": ("course_slider_crank", "mean_speed = -10.472", "mean_speed = -1e200",
                          ("dynamics", "mean_speed", "-1e+200")),
    "delta 5e-324": ("flying_shears", "delta = 0.08", "delta = 5e-324", ("dynamics", "delta", "5e-324")),
    "link inertia 1e308": ("flying_shears", "inertia = 0.106667", "inertia = 1e308",
                           ("link '2'", "inertia", "1e+308")),
    "inertia_0 1e308": ("course_slider_crank", "inertia_0 = 90.264", "inertia_0 = 1e308",
                        ("dynamics", "inertia_0", "1e+308")),
    "rotor inertia 1e308": ("flying_shears", "inertia = 0.0012", "inertia = 1e308",
                            ("dynamics", "rotors[0]", "inertia", "1e+308")),
    "overload 1e200": ("flying_shears", "overload = 2.2", "overload = 1e200",
                       ("dynamics", "motor (induction)", "overload", "1e+200")),
    # the mechanism
    "length nan": ("four_bar", "length = 0.3", "length = nan", ("link '2'", "length", "nan")),
    "length tiny": ("four_bar", "length = 0.3", "length = 1e-60", ("link '2'", "length", "1e-60")),
    "length a string": ("four_bar", "length = 0.3", 'length = "0.3"', ("link '2'", "length", "'0.3'")),
    "point 1e300": ("four_bar", "C = [0.3, 0.0]", "C = [1e300, 0.0]", ("link '0'", "point 'C'", "1e+300")),
    "point inf": ("four_bar", "C = [0.3, 0.0]", "C = [0.3, inf]", ("link '0'", "point 'C'", "inf")),
    "distance negative": ("four_bar", "distance = 0.15 }", "distance = -0.15 }",
                          ("link '2'", "point 'S2'", "distance", "-0.15")),
    "distance 1e300": ("four_bar", "distance = 0.15 }", "distance = 1e300 }",
                       ("link '2'", "point 'S2'", "distance", "1e+300")),
    "angle_deg 1e300": ("flying_shears", "angle_deg = -40", "angle_deg = 1e300",
                        ("link '2'", "point 'E'", "angle_deg", "1e+300")),
    "guide offset 1e300": ("slider_crank", "angle_deg = 0 }", "angle_deg = 0, offset = 1e300 }",
                           ("link '0'", "guide 'slide'", "offset", "1e+300")),
    "guide through 1e300": ("slider_crank", "through = [0.0, 0.01335]", "through = [0.0, 1e300]",
                            ("link '0'", "guide 'slide'", "1e+300")),
    "pair angle 1e300": ("slider_crank", 'guide = "slide"', 'guide = "slide"\nangle_deg = 1e300',
                         ("pairs.slide", "angle_deg", "1e+300")),
    "mass negative": ("four_bar", "mass = 3.0", "mass = -3.0", ("link '2'", "mass", "-3.0")),
    "mass 1e300": ("four_bar", "mass = 3.0", "mass = 1e300", ("link '2'", "mass", "1e+300")),
    "com 1e300": ("scotch_yoke", "com = [0.075, 0.0]", "com = [1e300, 0.0]", ("link '3'", "1e+300")),
    # loads
    "gravity 1e300": ("four_bar", "gravity = [0.0, -9.81]", "gravity = [0.0, -1e300]",
                      ("loads", "gravity", "-1e+300")),
    "force nan": ("slider_crank", "[loads]", '[loads]\nforces = [{ point = "B", link = "3", force = [nan, 0.0] }]',
                  ("loads", "forces[0]", "force", "nan")),
    "cycle value 1e300": ("course_slider_crank", "-125000]", "-1e300]", ("loads", "forces[0]", "cycle", "-1e+300")),
    "diagram value 1e300": ("flying_shears", "values = [0, 0, 2100, 0, 0]", "values = [0, 0, 1e300, 0, 0]",
                            ("loads", "forces[0]", "values", "1e+300")),
    "diagram value negative": ("flying_shears", "values = [0, 0, 2100, 0, 0]", "values = [0, 0, -2100, 0, 0]",
                               ("loads", "forces[0]", "values", "-2100")),
    "diagram fraction 1.5": ("flying_shears", "fractions = [0, 0.315,", "fractions = [0, 1.5,",
                             ("loads", "forces[0]", "fractions", "1.5")),
    "moment 1e300": ("four_bar", "[loads]", '[loads]\nmoments = [{ link = "3", moment = 1e300 }]',
                     ("loads", "moments[0]", "moment", "1e+300")),
    # dynamics
    "mean_rpm 0": ("flying_shears", "mean_rpm = 60", "mean_rpm = 0", ("dynamics", "mean_rpm", "0")),
    "delta 2": ("flying_shears", "delta = 0.08", "delta = 2", ("dynamics", "delta", "2")),
    "delta a string": ("flying_shears", "delta = 0.08", 'delta = "0.08"', ("dynamics", "delta", "'0.08'")),
    "positions 0": ("flying_shears", "positions = 72", "positions = 0", ("dynamics", "positions", "0")),
    "positions 1e9": ("flying_shears", "positions = 72", "positions = 1000000000",
                      ("dynamics", "positions", "1000000000")),
    "positions 2.5": ("flying_shears", "positions = 72", "positions = 2.5", ("dynamics", "positions", "2.5")),
    "cycles 1e6": ("flying_shears", "cycles = 12", "cycles = 1000000", ("dynamics", "cycles", "1000000")),
    "start_deg 1e300": ("flying_shears", "positions = 72", "positions = 72\nstart_deg = 1e300",
                        ("dynamics", "start_deg", "1e+300")),
    "rotor ratio 1e300": ("flying_shears", "ratio = 23.5 }]", "ratio = 1e300 }]",
                          ("dynamics", "rotors[0]", "ratio", "1e+300")),
    "initial_rpm negative": ("flying_shears", "initial_rpm = 6", "initial_rpm = -6",
                             ("dynamics", "initial_rpm", "-6")),
    "efficiency 1.5": ("flying_shears", "efficiency = 0.9", "efficiency = 1.5",
                       ("dynamics", "motor (induction)", "efficiency", "1.5")),
    "rated_power 1e300": ("flying_shears", "rated_power = 90.0", "rated_power = 1e300",
                          ("dynamics", "motor (induction)", "rated_power", "1e+300")),
    "synchronous_rpm nan": ("flying_shears", "synchronous_rpm = 1500", "synchronous_rpm = nan",
                            ("dynamics", "motor (induction)", "synchronous_rpm", "nan")),
    "overload 1": ("flying_shears", "overload = 2.2", "overload = 1", ("dynamics", "motor (induction)", "overload", "1")),
}


def with_loads(name: str, text: str) -> str:
    """The four-bar and the slider-crank texts carry a [loads] section; make sure of it."""
    return text if "[loads]" in text else text + "\n[loads]\ngravity = [0.0, -9.81]\n"


@pytest.mark.parametrize("case", list(RANGE_CASES))
def test_out_of_range_values_are_refused_at_load_time_naming_file_entry_and_value(tmp_path, case):
    scheme, old, new, parts = RANGE_CASES[case]
    path = write(tmp_path, file_name(case), edit(with_loads(scheme, text_of(scheme)), old, new))
    with pytest.raises(SchemeError, match=names(path, *parts)) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems


def test_the_bounds_leave_room_for_any_real_machine(tmp_path):
    """The ranges refuse only what would overflow: a machine a thousand times larger and one a
    thousand times smaller than the course press, heavy and fast, loads and analyses."""
    for factor in ("1e3", "1e-3"):
        text = text_of("course_slider_crank")
        for old in ("length = 0.0742", "length = 0.2225", "distance = 0.0741", "through = [0.0, 0.01335]"):
            number = re.search(r"[-\d.]+(?=\]?$)", old).group(0)
            text = edit(text, old, old.replace(number, f"{float(number) * float(factor)!r}"))
        text = edit(text, "mass = 400.0", "mass = 4e8")
        text = edit(text, "mean_speed = -10.472", "mean_speed = -1e4")
        mech = linkage.load(write(tmp_path, f"press_{factor}.toml", text))
        motion = linkage.analyze(mech, np.radians([0.0, 90.0]), omega=-1e4)
        assert np.isfinite(solve_reactions(motion).balancing_moment).all()


@pytest.mark.parametrize("k", [1e-45, 1e45])
def test_a_machine_at_the_edge_of_the_ranges_loads_and_analyses(k):
    """The four-bar with every length x k (masses 1 kg, no moments of inertia, which would leave
    their range): it loads with a moment diagram over the rocker's angle, its extreme positions
    are the unscaled ones (an angle's analog is not compared with the mechanism's size), and
    kinematics and reactions run without a floating-point warning."""
    data = to_dict(linkage.load("four_bar"))
    for spec in data["links"].values():
        spec["points"] = {p: [x * k, y * k] for p, (x, y) in spec["points"].items()}
        spec["com"] = [c * k for c in spec["com"]]
        spec["inertia"] = 0.0
        if spec.get("mass"):
            spec["mass"] = 1.0
    data["loads"] = {"moments": [{"link": "3", "diagram": {"working": "+", "fractions": [0, 1],
                                                           "values": [1.0, 1.0]}}]}
    data["checks"] = {"silence": ["lengths", "masses"]}  # meant: no plausibility note (1e45 m links)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mech = linkage.loads(linkage.dumps(from_dict(data)), source=f"four_bar_x{k:g}")
        ext, unscaled = linkage.extreme_positions(mech), linkage.extreme_positions(linkage.load("four_bar"))
        assert ext.phi_max == pytest.approx(unscaled.phi_max, abs=1e-9)
        assert ext.phi_min == pytest.approx(unscaled.phi_min, abs=1e-9)
        motion = linkage.analyze(mech, np.radians(np.arange(0.0, 360.0, 10.0)), omega=1.0)
        reactions = solve_reactions(motion)
    assert np.isfinite(reactions.balancing_moment).all()


# ----------------------------------------------------------------------------------------------
# structure first, one message per root cause
# ----------------------------------------------------------------------------------------------

MISSPELT_PAIR = ('[pairs.A]                         # crank pin\nlinks = ["1", "2"]',
                 '[pairs.A]                         # crank pin\nlink = ["1", "2"]')


def test_a_misspelt_pair_key_in_a_scheme_with_loads_is_reported_as_itself(tmp_path):
    """Issue 7, seen 7: the unknown key in pairs.A, with the file name, and nothing about
    mobility (nor about the missing 'links' it causes)."""
    text = text_of("flying_shears")
    assert "[loads]" in text and "[dynamics]" in text
    path = write(tmp_path, "misspelt_link.toml", edit(text, *MISSPELT_PAIR))
    with pytest.raises(SchemeError, match=names(path, "pairs.A", "unknown keys ['link']", "did you mean 'links'")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems
    assert "mobility" not in str(info.value)


@pytest.mark.parametrize("old, new, parts", [
    ("length = 0.1\n", "lenght = 0.1\n", ("links.1", "'lenght'", "did you mean 'length'")),
    ('input = "1"', 'inpt = "1"', ("top-level", "'inpt'", "did you mean 'input'")),
    ("[pairs.A]\nlinks", "[pairs.A]\nlinx", ("pairs.A", "'linx'", "did you mean 'links'")),
])
def test_a_misspelt_key_gives_one_message_not_its_follow_ons(tmp_path, old, new, parts):
    path = write(tmp_path, "misspelt.toml", edit(text_of("four_bar"), old, new))
    with pytest.raises(SchemeError, match=names(path, *parts)) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems


def test_a_refused_line_does_not_report_the_pairs_pinned_at_its_points(tmp_path):
    path = write(tmp_path, "bad_line.toml", edit(text_of("four_bar"), "length = 0.25", "length = -0.25"))
    with pytest.raises(SchemeError, match=names(path, "link '3'", "length", "-0.25")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems


def test_prismatic_links_in_the_wrong_order_are_one_message(tmp_path):
    text = edit(text_of("slider_crank"), 'links = ["0", "3"]', 'links = ["3", "0"]')
    path = write(tmp_path, "slide_reversed.toml", text)
    with pytest.raises(SchemeError, match=names(path, "pair 'slide'", "wrong order", "[guide link, slider link]")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems


def test_structure_problems_come_before_loads_and_dynamics(tmp_path):
    """A wrong mobility and a bad [loads] entry: the structure is reported, the loads are not
    parsed (they cannot be: a diagram needs the kinematics of a sound structure)."""
    text = edit(text_of("flying_shears"), "[pairs.C]                         # rocker bearing\nlinks = [\"3\", \"0\"]\n", "")
    text = edit(text, 'point = "E"', 'point = "Q"')
    path = write(tmp_path, "no_pair_C.toml", text)
    with pytest.raises(SchemeError, match=names(path, "mobility")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1 and "'Q'" not in str(info.value), info.value.problems
    # with the structure repaired, the loads problem is reported, naming its entry
    path = write(tmp_path, "bad_point.toml", edit(text_of("flying_shears"), 'point = "E"', 'point = "Q"'))
    with pytest.raises(SchemeError, match=names(path, "loads", "forces[0]", "'Q'")):
        linkage.load(path)


def test_declaration_problems_come_before_the_structure(tmp_path):
    """A bad value and a missing pair: the bad value is reported, not the mobility it hides."""
    text = edit(text_of("four_bar"), '[pairs.C]\nlinks = ["3", "0"]\n', "")
    text = edit(text, "length = 0.3", "length = nan")
    path = write(tmp_path, "nan_and_pair.toml", text)
    with pytest.raises(SchemeError, match=names(path, "link '2'", "length", "nan")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems


def test_bad_dynamics_and_a_cycle_table_that_needs_it_are_one_message(tmp_path):
    """The cycle table reads the cycle of [dynamics]: a bad mean speed is reported once, as
    itself, not again as "a cycle table needs the direction of rotation"."""
    path = write(tmp_path, "no_speed.toml", edit(text_of("course_slider_crank"), "mean_speed = -10.472",
                                                 "mean_speed = 0"))
    with pytest.raises(SchemeError, match=names(path, "dynamics", "mean_speed", "0")) as info:
        linkage.load(path)
    assert len(info.value.problems) == 1, info.value.problems
    # the same section attached to a built mechanism: loads_of reports the dynamics too
    mech = linkage.load("course_slider_crank")
    broken = mech.with_extra(dynamics={**mech.extra["dynamics"], "mean_speed": 0})
    with pytest.raises(SchemeError, match="dynamics.*mean_speed"):
        loads_of(broken)


# ----------------------------------------------------------------------------------------------
# parse once
# ----------------------------------------------------------------------------------------------


def test_loads_and_dynamics_are_parsed_once_at_load_time(monkeypatch):
    mech = linkage.load("course_slider_crank")
    assert set(mech.parts) == {"loads", "dynamics", "checks", "friction"}
    loads, spec = loads_of(mech), dynamics_of(mech)
    calls = []
    for section in ("loads", "dynamics"):
        parser = SECTION_PARSERS[section]
        monkeypatch.setitem(SECTION_PARSERS, section,
                            lambda m, raw, parser=parser, section=section: calls.append(section) or parser(m, raw))
    assert loads_of(mech) is loads and dynamics_of(mech) is spec
    motion = linkage.analyze(mech, np.radians(np.arange(0.0, 360.0, 30.0)), omega=spec.mean_speed)
    solve_reactions(motion)
    linkage.dynamics.course_method(mech)
    assert calls == []
    # a mechanism built in Python is parsed on first use, once
    built = mech.with_extra(loads={"gravity": [0.0, 0.0]})
    assert loads_of(built).gravity == (0.0, 0.0) and loads_of(built) is loads_of(built)
    assert calls == ["dynamics", "loads"]  # the loads read the cycle of the dynamics


def test_reactions_use_the_stroke_ends_found_at_load_time(monkeypatch):
    """Force diagrams carry their stroke ends and cycle tables their first position: the
    reactions do not re-run kinematics to find them."""
    shears, press = linkage.load("flying_shears"), linkage.load("course_slider_crank")
    (knife,) = loads_of(shears).forces
    assert isinstance(knife.force, StrokeDiagram)
    ext = linkage.extreme_positions(shears, "E.y")
    assert knife.force.stroke_ends == (ext.value_min, ext.value_max)
    (cut,) = loads_of(press).forces
    assert cut.force.phi0 == pytest.approx(linkage.table_angles(press, 12, "extreme", -1)[0], abs=1e-12)
    phi = np.radians(np.arange(0.0, 360.0, 5.0))
    before = {m.name: solve_reactions(linkage.analyze(m, phi, omega=-1.0)).balancing_moment for m in (shears, press)}

    def no_kinematics(*args, **kwargs):
        raise AssertionError("stroke ends re-derived")

    monkeypatch.setattr(linkage.kinetostatics.loads, "extreme_positions", no_kinematics)
    monkeypatch.setattr(linkage.kinetostatics.loads, "table_angles", no_kinematics)
    for m in (shears, press):
        after = solve_reactions(linkage.analyze(m, phi, omega=-1.0)).balancing_moment
        np.testing.assert_array_equal(after, before[m.name])
    # the knife force is really there: the reactions differ without it
    bare = solve_reactions(linkage.analyze(shears, phi, omega=-1.0), loads_of(shears.with_extra(loads={})))
    assert not np.allclose(bare.balancing_moment, before["flying_shears"])


def test_parts_are_not_part_of_equality():
    a, b = linkage.load("flying_shears"), linkage.load("flying_shears")
    loads_of(a)
    assert a == b and linkage.loads(linkage.dumps(a)) == a


# ----------------------------------------------------------------------------------------------
# every error of the library is a LinkageError
# ----------------------------------------------------------------------------------------------


def _bad_calls():
    four_bar = linkage.load("four_bar")
    motion1 = linkage.analyze(four_bar, [0.0, 1.0], order=1)
    motion2 = linkage.analyze(four_bar, [0.0, 1.0])
    no_output = linkage.MechanismBuilder("no_output")
    no_output.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)}).link("1", line=("O", "A"), length=0.1)
    no_output.link("2", line=("A", "B"), length=0.3).link("3", line=("C", "B"), length=0.25)
    for name, a, c in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "0")]:
        no_output.revolute(name, a, c)
    no_output = no_output.inputs("1").assembly("B", left_of=("A", "C")).build()
    return {
        "reactions of an order-1 motion": (lambda: solve_reactions(motion1), InputError),
        "moment of a revolute pair": (lambda: solve_reactions(motion2).moment("A"), InputError),
        "no pair joins": (lambda: solve_reactions(motion2).on("1", "3"), InputError),
        "inertia without speed": (lambda: inertia_terms(motion2), InputError),
        "force of a wrong shape": (lambda: evaluate_loads(motion2, linkage.kinetostatics.loads.Loads(
            forces=(linkage.kinetostatics.loads.PointForce("E", "2", np.zeros((5, 2))),))), InputError),
        "no [dynamics]": (lambda: dynamics_of(four_bar), SchemeError),
        "no output": (lambda: linkage.extreme_positions(no_output), InputError),
        "zero positions": (lambda: linkage.table_angles(four_bar, 0), InputError),
        "bad table format": (lambda: linkage.report.format_columns({"a": np.zeros(2)}, "xml"), InputError),
        "unwritable extra": (lambda: linkage.dumps(four_bar.with_extra(loads={"gravity": object()})), SchemeError),
        "bad builder angle": (lambda: linkage.MechanismBuilder("x").prismatic("K", "0", "1", guide="g", at="P",
                                                                              angle="up").build(), SchemeError),
    }


@pytest.mark.parametrize("case", list(_bad_calls()))
def test_errors_raised_on_purpose_are_linkage_errors_and_value_errors(case):
    call, kind = _bad_calls()[case]
    with pytest.raises(kind) as info:
        call()
    assert isinstance(info.value, LinkageError) and isinstance(info.value, ValueError)


# ----------------------------------------------------------------------------------------------
# the command line: exit status 2, one line per problem, no traceback, no numpy warning
# ----------------------------------------------------------------------------------------------

CLI_FILE_CASES = {
    "length 1e200": ("course_slider_crank", "length = 0.0742", "length = 1e200", ("link '1'", "length", "1e+200")),
    "mean_speed -1e200": ("course_slider_crank", "mean_speed = -10.472", "mean_speed = -1e200",
                          ("dynamics", "mean_speed", "-1e+200")),
    "delta 5e-324": ("flying_shears", "delta = 0.08", "delta = 5e-324", ("dynamics", "delta", "5e-324")),
    "flywheel 1e308": ("flying_shears", "cycles = 12", "cycles = 12\nflywheel = 1e308",
                       ("dynamics", "flywheel", "1e+308")),
    "overload 1e200": ("flying_shears", "overload = 2.2", "overload = 1e200", ("overload", "1e+200")),
    "misspelt link": ("flying_shears", *MISSPELT_PAIR, ("pairs.A", "'link'")),
}


@pytest.mark.parametrize("command", [["analyze"], ["forces"], ["dynamics", "--method", "ode"]])
@pytest.mark.parametrize("case", list(CLI_FILE_CASES))
def test_cli_refuses_absurd_schemes_with_status_2_and_no_traceback(capsys, tmp_path, case, command):
    scheme, old, new, parts = CLI_FILE_CASES[case]
    path = write(tmp_path, file_name(case), edit(text_of(scheme), old, new))
    code, out, err = run(capsys, command[0], path, *command[1:])
    assert code == 2 and out == "", err
    assert "Traceback" not in err and "Warning" not in err, err
    assert re.search(r"(?m)^linkage: error: " + re.escape(str(path)) + ".*" + ".*".join(map(re.escape, parts)), err), err
    assert len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("argv", [
    ["forces", "slider_crank", "--omega", "1e300"],
    ["forces", "slider_crank", "--rpm", "nan"],
    ["forces", "slider_crank", "--eps", "inf"],
    ["dynamics", "course_slider_crank", "--delta", "nan"],
    ["analyze", "four_bar", "--positions", "100000000000"],
    ["analyze", "four_bar", "--start", "1e300"],
])
def test_cli_refuses_absurd_options_with_status_2(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == "" and "Traceback" not in err, err
    assert argv[-2] in err and argv[-1] in err


def test_cli_never_prints_a_numpy_warning_or_a_traceback(capsys, monkeypatch):
    """The safety nets: a floating-point warning inside a command becomes one line in the
    library's words; an unexpected exception (a bug) one ``internal error`` line, status 1."""
    real = linkage.report.results.analyze

    def noisy(*args, **kwargs):
        with np.errstate(over="warn"):
            np.float64(1e300) * np.float64(1e300)
        warnings.warn("a library warning", UserWarning)
        return real(*args, **kwargs)

    monkeypatch.setattr(linkage.report.results, "analyze", noisy)
    code, out, err = run(capsys, "forces", "four_bar")
    assert code == 0 and out
    assert "RuntimeWarning" not in err and "overflow encountered" not in err, err
    assert "linkage: warning: a floating-point overflow or invalid value occurred" in err
    assert "linkage: warning: a library warning" in err

    def broken(*args, **kwargs):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(linkage.report.results, "analyze", broken)
    code, out, err = run(capsys, "forces", "four_bar")
    assert code == 1 and out == "" and "Traceback" not in err
    assert err.strip() == ("linkage: error: internal error (ZeroDivisionError: division by zero); please "
                           "report it with the command line that caused it")


def test_a_folder_or_a_binary_file_is_named_as_such(tmp_path):
    with pytest.raises(SchemeError, match="is a folder, not a scheme file"):
        linkage.load(tmp_path)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"name = \"x\"\n\xd0\xff\x00")
    with pytest.raises(SchemeError, match=r"binary\.toml: not a text file in UTF-8 \(byte 11"):
        linkage.load(binary)
