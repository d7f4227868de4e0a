"""``linkage enumerate``: every R/P assignment of a chain, each written as a scheme that runs a full turn.

The expected assignments are counted by hand from the dyad kinds' rules and checked against the
rank of each group's constraint Jacobian at random poses with random dimensions (computed here);
the figures of the combinations are checked against closed forms of the mechanisms they must be
(the central and the offset slider-crank, the slotted link whose slot passes through its pivot),
against the shipped scheme the unchanged combination is, and, for groups solved by Newton's
method, against the closure of every pair computed here from the points' coordinates.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

import linkage
from assur.base import PrismaticJoint, RevoluteJoint
from assur.generic import NewtonGroup
from linkage.cli import main
from linkage.research import Enumeration, assignments, build_combination, enumerate_chain, measure
from linkage.errors import InputError, StructureError
from linkage.kinetostatics.reactions import solve_reactions
from linkage.model.mechanism import Prismatic, Revolute

CLOSED_FORM_KINDS = {"RRR", "RRP", "RPR", "PRP", "RPP"}
TURN = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)


@pytest.fixture(scope="module")
def four_bar():
    return enumerate_chain("four_bar", newton=True)


@pytest.fixture(scope="module")
def slider_crank():
    return enumerate_chain("slider_crank", newton=True)


def row(found, ident):
    (match,) = [c for c in found.combinations if c.id == ident]
    return match


def closed_form_by_hand() -> set[str]:
    """The four-bar's group is links 2, 3 with the external pairs A (1-2), C (3-0) and the inner
    pair B (2-3). A dyad kind wants the guide of an external P pair on the known link (A on 1, C
    on 0) and takes an inner P pair with the guide on either link; PPP and RRR-with-a-wrong-guide
    have no closed form. So: RRR; RRP (C on 0); PRR (A on 1); RPR twice (B on 2 or on 3); PRP (A on 1,
    C on 0); RPP (B on 3, C on 0: the slider of C carries the slot); PPR (A on 1, B on 2)."""
    return {"A=R,B=R,C=R", "A=R,B=R,C=P0", "A=P1,B=R,C=R", "A=R,B=P2,C=R", "A=R,B=P3,C=R",
            "A=P1,B=R,C=P0", "A=R,B=P3,C=P0", "A=P1,B=P2,C=R"}


def four_bar_by_hand() -> set[str]:
    """Every assignment but the 2 * 2 * 2 with A, B and C all prismatic: those fix the angle of
    link 2 to the crank (A), of link 3 to the frame (C) and of 2 to 3 (B), so the crank could not
    turn. The other 19 are solvable: the 8 closed forms and 11 groups solved by Newton's method."""
    every = {a.id for a in assignments(linkage.load("four_bar"))}
    return every - {f"A=P{a},B=P{b},C=P{c}" for a in "12" for b in "23" for c in "03"}


def dependent_whatever_the_dimensions(source, assignment, rng) -> bool:
    """Whether a group of the combination has dependent equations at every pose and for every
    geometry: the rank of its constraint Jacobian (``assur.base.Group.jacobians``) at 4 random
    poses, with random local points, guide directions and slider angles, is below 3 per link."""
    kinds = {k.pair: k for k in assignment.kinds}
    joints = []
    for name, pair in source.pairs.items():
        kind = kinds.get(name)
        a, b = pair.links
        if kind is None or kind.kind == "R":
            joints.append(RevoluteJoint(name, a, b, tuple(rng.normal(size=2)), tuple(rng.normal(size=2))))
        else:
            slider = b if kind.guide_link == a else a
            u = rng.normal(size=2)
            joints.append(PrismaticJoint(name, kind.guide_link, slider, tuple(rng.normal(size=2)),
                                         tuple(u / np.linalg.norm(u)), tuple(rng.normal(size=2)), rng.normal()))
    placed = {source.frame, *source.inputs}
    for links in (g.links for g in linkage.structure_of(source).groups):
        own = [j for j in joints if {j.a, j.b} & set(links) and {j.a, j.b} <= placed | set(links)]
        group = NewtonGroup(links, own, 1.0)
        poses = {k: rng.normal(size=(4, 3)) for k in {*links, *group.known_links}}
        phi_q = group.jacobians(poses)[0]
        singular_values = np.linalg.svd(phi_q, compute_uv=False)
        if np.all(np.sum(singular_values > 1e-9 * singular_values[:, :1], axis=1) < 3 * len(links)):
            return True
        placed |= set(links)
    return False


def test_four_bar_gives_the_assignments_counted_by_hand():
    found = enumerate_chain("four_bar", geometry=False)
    assert len(assignments(linkage.load("four_bar"))) == 3**3    # R, P on either link, for A, B, C
    assert {c.id for c in found.combinations} == four_bar_by_hand()
    closed = {c.id for c in found.combinations if "II-" in c.formula}      # a kind named: a closed form
    assert closed == closed_form_by_hand()
    assert len(found.rejected) == 8
    reasons = {r.id: r.reason for r in found.rejected}
    assert "A: P guide 1 / slider 2, B: P guide 2 / slider 3, C: P guide 0 / slider 3" in reasons["A=P1,B=P2,C=P0"]
    assert "fix one angle twice" in reasons["A=P1,B=P2,C=P0"]


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


def test_a_dyad_solved_by_newtons_method_moves_as_its_closed_form_twin(four_bar):
    """C=P3: the rocker 3 carries the guide and the frame's point C slides in it -- the same
    constraint as the frame's guide along the same line (C=P0, the guide rule runs both along the
    line O-B of the reference position): link 3 keeps its angle and slides along that line. The
    first is a group solved by Newton's method, the second the RRP closed form; both are the
    central slider-crank, stroke 2 r, and move alike, with the same balancing moment."""
    traced, closed = row(four_bar, "A=R,B=R,C=P3"), row(four_bar, "A=R,B=R,C=P0")
    assert traced.formula == "I(0,1) → II(2,3)" and closed.formula == "I(0,1) → II-RRP(2,3)"
    assert traced.full_turn and traced.stroke == pytest.approx(2 * 0.1, rel=1e-9)
    assert traced.peak_balancing_moment == pytest.approx(closed.peak_balancing_moment, rel=1e-7)
    motions = [linkage.analyze(linkage.loads(c.scheme), TURN) for c in (traced, closed)]
    size = linkage.load("four_bar").size
    for link in ("2", "3"):
        gap = motions[0].poses[link] - motions[1].poses[link]
        assert np.max(np.abs(gap[:, :2])) <= 1e-9 * size
        assert np.max(np.abs(np.angle(np.exp(1j * gap[:, 2])))) <= 1e-9


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
    assert len(found.combinations) == 19 * 19      # two dyads, each as the four-bar's: 19 kinds each
    rng = np.random.default_rng(7)
    dependent = {a.id for a in assignments(source) if dependent_whatever_the_dimensions(source, a, rng)}
    assert {r.id for r in found.rejected} == dependent
    closed = [c for c in found.combinations if c.formula.count("II-") == 2]
    assert len(closed) == 8 * 8
    for combination in closed:
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
    assert len(read_rows((out / "rejected.csv").read_text(encoding="utf-8"))) == 8
    code = main(["analyze", str(out / f"{running[0]}.toml"), "--positions", "12"])
    assert code == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main(["enumerate", "four_bar"]) == 0
    table = capsys.readouterr().out
    assert "# assignments: 27: 19 decompose" in table and "peak_balancing_moment" in table


@pytest.mark.parametrize("argv, named", [
    (["enumerate", "no_such_chain"], "no_such_chain"),
    (["enumerate", "four_bar", "--omega", "0"], "--omega 0"),
    (["enumerate", "cylinder_boom"], "input 'K' is a slide (driven by the prismatic pair 'K')"),
    (["enumerate", "piston_driven_crank"], "input '3' is a slide (driven by the prismatic pair 'slide')"),
    (["enumerate", "five_bar_two_input"], "has 2 input links ['1', '4']"),
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


# ----------------------------------------------------------------------------------------------
# groups solved by Newton's method: the class-III triad of six_bar_class3 and its sliders
# ----------------------------------------------------------------------------------------------

CLASS3 = "six_bar_class3"
ALL_REVOLUTE = "A=R,B=R,C=R,D=R,E=R,F=R"
SLOT_IN_TERNARY = "A=R,B=R,C=R,D=P3,E=R,F=R"        # D slides in a slot of the ternary link 3


@pytest.fixture(scope="module")
def class3_kept():
    return {c.id for c in enumerate_chain(CLASS3, geometry=False).combinations}


def global_points(motion, mech, link: str, local) -> np.ndarray:
    """Global position ``(N, 2)`` of the local point ``local`` of ``link`` at the analysed poses, m."""
    x, y, theta = motion.poses[link].T
    c, s = np.cos(theta), np.sin(theta)
    return np.column_stack([x + c * local[0] - s * local[1], y + s * local[0] + c * local[1]])


def pair_openings(mech, motion) -> np.ndarray:
    """The largest opening ``(N,)``, m, of every pair at the analysed positions, from the links'
    poses and the points and guides declared on them: a revolute pair's two pins apart; a
    prismatic pair's slider point off its guide line, and the size times the error of the
    slider's angle to the guide."""
    gaps = []
    for pair in mech.pairs.values():
        a, b = pair.links
        if isinstance(pair, Revolute):
            pins = [global_points(motion, mech, k, mech.links[k].points[pair.point]) for k in (a, b)]
            gaps.append(np.linalg.norm(pins[0] - pins[1], axis=1))
            continue
        guide = mech.links[a].guides[pair.guide]
        direction = motion.poses[a][:, 2] + guide.angle
        normal = np.column_stack([-np.sin(direction), np.cos(direction)])
        off = global_points(motion, mech, b, mech.links[b].points[pair.point]) - global_points(motion, mech, a,
                                                                                               guide.point)
        turned = motion.poses[b][:, 2] - direction - pair.angle
        gaps += [np.abs(np.sum(off * normal, axis=1)), mech.size * np.abs(np.angle(np.exp(1j * turned)))]
    return np.max(gaps, axis=0)


def written_and_reloaded(combination, tmp_path):
    """The combination's scheme written by :meth:`Enumeration.write` and loaded back by path."""
    Enumeration(CLASS3, 10.0, (combination.reference_deg,), (combination,), ()).write(tmp_path)
    return linkage.load(tmp_path / combination.assignment.file_name)


def test_the_all_revolute_triad_is_kept_and_is_the_shipped_scheme(class3_kept, tmp_path):
    """The unchanged chain of six_bar_class3 (a class-III group: before, every assignment was
    rejected) is kept, written with a readable condition, and moves exactly as the shipped scheme."""
    assert ALL_REVOLUTE in class3_kept
    triad = measure(CLASS3, ALL_REVOLUTE)
    assert triad.full_turn and triad.crank_factor == 1.0, triad.note
    mech = written_and_reloaded(triad, tmp_path)
    assert "III(2,3,4,5)" in linkage.structure_of(mech).formula
    assert [a.rule for a in mech.assembly] in (["left_of"], ["right_of"])
    source = linkage.load(CLASS3)
    phi = np.concatenate([TURN, np.radians([triad.reference_deg])])
    mine, shipped = (linkage.analyze(m, phi, on_failure="mask") for m in (mech, source))
    assert np.all(mine.status == 0) and np.all(shipped.status == 0)
    for point in source.point_names:
        assert np.max(np.abs(mine.point(point) - shipped.point(point))) <= 1e-9 * source.size, point


def test_a_triad_with_a_slider_is_kept_and_its_written_scheme_closes(class3_kept, tmp_path):
    """D prismatic, sliding in a slot of the ternary link: no closed form (a NewtonGroup). The
    written scheme runs a full turn and every pair closes, computed here from the coordinates."""
    assert SLOT_IN_TERNARY in class3_kept
    slotted = measure(CLASS3, SLOT_IN_TERNARY)
    assert slotted.full_turn, slotted.note
    mech = written_and_reloaded(slotted, tmp_path)
    (group,) = linkage.structure_of(mech).groups
    assert isinstance(group, NewtonGroup) and group.kind == "N" and repr(group) == "III(2,3,4,5)"
    assert isinstance(mech.pairs["D"], Prismatic) and mech.pairs["D"].links[0] == "3"
    motion = linkage.analyze(mech, np.radians(np.arange(0.0, 360.0, 10.0)), on_failure="mask")
    assert np.all(motion.status == 0)
    assert np.max(pair_openings(mech, motion)) <= 1e-9 * mech.size
    # the geometry at the reference angle is the source's: the points it shares with the source
    source = linkage.load(CLASS3)
    at = [np.radians(slotted.reference_deg)]
    mine, shipped = (linkage.analyze(m, at) for m in (mech, source))
    for point in ("O", "A", "B", "C", "D", "E", "F"):
        assert np.max(np.abs(mine.point(point) - shipped.point(point))) <= 1e-9 * source.size, point


def test_measure_refuses_a_rejected_or_unknown_assignment():
    with pytest.raises(StructureError, match="fix one angle twice"):
        measure("four_bar", "A=P1,B=P2,C=P0")
    with pytest.raises(InputError, match="A=Q"):
        measure("four_bar", "A=Q,B=R,C=R")


def test_traced_combinations_are_listed_not_searched_by_default(four_bar, capsys):
    """Without newton=True the combinations with a traced group are listed as "not searched" (no
    geometry, no file); the closed-form ones are measured exactly as with it."""
    quick = enumerate_chain("four_bar")
    assert [c.id for c in quick.combinations] == [c.id for c in four_bar.combinations]
    for fast, full in zip(quick.combinations, four_bar.combinations):
        traced = "II(" in fast.formula and "II-" not in fast.formula     # II(2,3): Newton's method, II-RRR(2,3): a dyad
        if traced:
            assert fast.full_turn is None and fast.scheme is None and "--newton" in fast.note
        else:
            assert fast == full
    assert sum(c.full_turn is None for c in quick.combinations) == 11
    assert list(quick.columns()["full_turn"]).count("not searched") == 11
    assert main(["enumerate", "four_bar"]) == 0
    out = capsys.readouterr().out
    assert "11 with a traced group not searched, see --newton" in out
