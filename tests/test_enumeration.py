"""``linkage enumerate``: every R/P assignment of a chain, each written as a scheme that runs a full turn.

The expected assignments are counted by hand from the dyad kinds' rules; the figures of the
combinations are checked against closed forms of the mechanisms they must be (the central and the
offset slider-crank, the slotted link whose slot passes through its pivot) and against the shipped
scheme the unchanged combination is.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

import linkage
from linkage.cli import main
from linkage.enumeration import assignments, build_combination, enumerate_chain
from linkage.kinetostatics import solve_reactions
from linkage.model import Prismatic, Revolute

CLOSED_FORM_KINDS = {"RRR", "RRP", "RPR", "PRP", "RPP"}
TURN = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)


@pytest.fixture(scope="module")
def four_bar():
    return enumerate_chain("four_bar")


@pytest.fixture(scope="module")
def slider_crank():
    return enumerate_chain("slider_crank")


def row(found, ident):
    (match,) = [c for c in found.combinations if c.id == ident]
    return match


def four_bar_by_hand() -> set[str]:
    """The four-bar's group is links 2, 3 with the external pairs A (1-2), C (3-0) and the inner
    pair B (2-3). A dyad kind wants the guide of an external P pair on the known link (A on 1, C
    on 0) and takes an inner P pair with the guide on either link; PPP and RRR-with-a-wrong-guide
    have no solver. So: RRR; RRP (C on 0); PRR (A on 1); RPR twice (B on 2 or on 3); PRP (A on 1,
    C on 0); RPP (B on 3, C on 0: the slider of C carries the slot); PPR (A on 1, B on 2)."""
    return {"A=R,B=R,C=R", "A=R,B=R,C=P0", "A=P1,B=R,C=R", "A=R,B=P2,C=R", "A=R,B=P3,C=R",
            "A=P1,B=R,C=P0", "A=R,B=P3,C=P0", "A=P1,B=P2,C=R"}


def test_four_bar_gives_the_assignments_counted_by_hand():
    found = enumerate_chain("four_bar", geometry=False)
    assert len(assignments(linkage.load("four_bar"))) == 3**3    # R, P on either link, for A, B, C
    assert {c.id for c in found.combinations} == four_bar_by_hand()
    assert len(found.rejected) == 27 - 8
    reasons = {r.id: r.reason for r in found.rejected}
    assert "C: P guide 3 / slider 0" in reasons["A=R,B=R,C=P3"]              # the guide on the moving link
    assert "has no closed-form solver" in reasons["A=R,B=P2,C=P0"]


def test_every_written_scheme_loads_and_runs_a_full_turn(four_bar, tmp_path):
    files = four_bar.write(tmp_path)
    written = sorted(p.name for p in files if p.suffix == ".toml")
    running = [c for c in four_bar.combinations if c.full_turn]
    assert written == sorted(c.assignment.file_name for c in running)
    assert len(running) >= 5
    for combination in running:
        mech = linkage.load(tmp_path / combination.assignment.file_name)
        motion = linkage.analyze(mech, TURN, on_failure="mask")
        assert np.all(motion.status == 0), combination.id
        for kind in combination.assignment.kinds:       # the file has the pair kinds of its id
            pair = mech.pairs[kind.pair]
            if kind.kind == "R":
                assert isinstance(pair, Revolute)
            else:
                assert isinstance(pair, Prismatic) and pair.links[0] == kind.guide_link
        assert linkage.structure_of(mech).formula == combination.formula


def test_the_unchanged_chain_is_the_source_scheme(four_bar):
    """Same geometry and masses: the same rocker swing and balancing moment as the shipped scheme."""
    same = row(four_bar, "A=R,B=R,C=R")
    assert same.crank_factor == 1.0 and same.output == "3.theta"
    source = linkage.load("four_bar")
    assert same.stroke == pytest.approx(math.degrees(linkage.extreme_positions(source).stroke), rel=1e-9)
    motion = linkage.analyze(source, TURN, omega=10.0)
    peak = np.max(np.abs(solve_reactions(motion).balancing_moment))
    assert same.peak_balancing_moment == pytest.approx(peak, rel=1e-9)


def test_four_bar_slider_and_slotted_link_follow_the_guide_rule(four_bar):
    """The guide runs from the guide link's nearest other joint towards the slider's: C on the frame
    gives the central slider-crank (stroke 2 r); B's slot in the rocker passes through its pivot C,
    so the rocker swings by 2 asin(r / OC) (the slotted link), whichever link carries the slot."""
    r, oc = 0.1, 0.3
    central = row(four_bar, "A=R,B=R,C=P0")
    assert central.output == "C.s" and central.stroke_unit == "m"
    assert central.stroke == pytest.approx(2 * r, rel=1e-9)
    for ident in ("A=R,B=P3,C=R", "A=R,B=P2,C=R"):
        slotted = row(four_bar, ident)
        assert slotted.stroke_unit == "deg"
        assert slotted.stroke == pytest.approx(2 * math.degrees(math.asin(r / oc)), rel=1e-9)
        assert slotted.min_transmission_angle_deg is None         # RPR: no inner revolute pair


def test_slider_crank_combination_of_the_shipped_topology_has_the_closed_form_stroke(slider_crank):
    crank, rod, offset = 0.0742, 0.2225, 0.01335
    stroke = math.sqrt((rod + crank) ** 2 - offset**2) - math.sqrt((rod - crank) ** 2 - offset**2)
    shipped = row(slider_crank, "A=R,B=R,slide=P0")
    assert shipped.full_turn and shipped.crank_factor == 1.0 and shipped.output == "B.x"
    assert shipped.stroke == pytest.approx(stroke, rel=1e-10)
    # transmission angle: 90 deg minus the rod's largest inclination, asin((r + e) / l)
    assert shipped.min_transmission_angle_deg == pytest.approx(
        90 - math.degrees(math.asin((crank + offset) / rod)), abs=1e-4)


def test_combinations_that_cannot_turn_say_why_and_are_not_written(slider_crank, tmp_path):
    pinned = row(slider_crank, "A=R,B=R,slide=R")      # the slider pinned where it was: a zero-length link
    assert not pinned.full_turn and pinned.scheme is None
    assert pinned.note.startswith("no full-turn geometry found")
    files = {p.name for p in slider_crank.write(tmp_path)}
    assert pinned.assignment.file_name not in files


def test_six_bar_enumerates_and_every_formula_decomposes():
    found = enumerate_chain("six_bar", geometry=False)
    source = linkage.load("six_bar")
    assert len(found.combinations) + len(found.rejected) == 3**6
    assert len(found.combinations) == 8 * 8       # two dyads, each as the four-bar's: 8 kinds each
    for combination in found.combinations:
        structure = linkage.structure_of(build_combination(source, combination.assignment))
        assert structure.formula == combination.formula
        assert {g.kind for g in structure.groups} <= CLOSED_FORM_KINDS


def read_rows(text: str) -> list[dict]:
    return list(csv.DictReader(io.StringIO(text)))


def test_cli_writes_the_table_and_the_schemes(capsys, tmp_path):
    out = tmp_path / "combinations"
    code = main(["enumerate", "four_bar", "--out", str(out), "--format", "csv"])
    printed, err = capsys.readouterr()
    assert code == 0, err
    rows = read_rows(printed)
    assert list(rows[0]) == ["id", "formula", "full_turn", "crank_factor", "reference_deg", "output", "stroke",
                             "stroke_unit", "min_transmission_angle_deg", "peak_balancing_moment", "note"]
    assert {r["id"] for r in rows} == four_bar_by_hand()
    assert read_rows((out / "combinations.csv").read_text(encoding="utf-8")) == rows
    running = [r["id"] for r in rows if r["full_turn"] == "yes"]
    assert sorted(p.name for p in out.glob("*.toml")) == sorted(f"{i}.toml" for i in running)
    assert len(read_rows((out / "rejected.csv").read_text(encoding="utf-8"))) == 19
    code = main(["analyze", str(out / f"{running[0]}.toml"), "--positions", "12"])
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main(["enumerate", "four_bar"]) == 0
    table = capsys.readouterr().out
    assert "# assignments: 27: 8 decompose" in table and "peak_balancing_moment" in table


@pytest.mark.parametrize("argv, named", [
    (["enumerate", "no_such_chain"], "no_such_chain"),
    (["enumerate", "four_bar", "--omega", "0"], "--omega 0"),
])
def test_cli_refuses_bad_input_naming_it(capsys, argv, named):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert named in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_cli_refuses_an_unwritable_folder(capsys, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder", encoding="utf-8")
    assert main(["enumerate", "four_bar", "--out", str(blocker / "inside")]) == 2
    err = capsys.readouterr().err
    assert str(blocker / "inside") in err and "cannot be written" in err
