"""Structure (docs/methods.md#structure) and the structural invariants of kinematics (docs/methods.md#checks).

- mobility by Chebyshev's formula, counted by hand (``W = 3 n - 2 p``) for the shipped schemes;
- structural formulas of the shipped schemes and of builder-made mechanisms, derived by hand;
- the decomposition and the analysed motion do not depend on the order of declaration;
- StructureError / SchemeError for W != inputs and for mechanisms that cannot be decomposed;
- mirror invariance (x -> -x) and scale invariance (lengths x k) of positions and analogs.
"""

from __future__ import annotations

import copy
import math
import random
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage import MechanismBuilder, SchemeError, StructureError
from linkage.model.scheme import from_dict, to_dict

SCHEMES_DIR = Path(__file__).resolve().parent.parent / "schemes"
SHIPPED = sorted(p.stem for p in SCHEMES_DIR.glob("*.toml"))

#: input angles away from the singular positions of the shipped schemes
PHI = 0.1 + np.arange(24) * (2 * np.pi / 24)


def positions(mech: linkage.Mechanism) -> np.ndarray:
    """The sampled input coordinates: PHI (rad) for a crank; 24 slides (m) inside the declared
    stroke of a slide input."""
    if mech.coordinate.is_angle:
        return PHI
    a, b = mech.input_range
    return a + (b - a) * (np.arange(24) + 0.5) / 24

# ----------------------------------------------------------------------------------------------
# mobility
# ----------------------------------------------------------------------------------------------

#: W = 3 n - 2 p, with n moving links and p lower pairs counted in each scheme file by hand
HAND_MOBILITY = {
    "four_bar": 3 * 3 - 2 * 4,               # links 1 2 3; pairs O A B C
    "flying_shears": 3 * 3 - 2 * 4,          # links 1 2 3; pairs O A B C
    "slider_crank": 3 * 3 - 2 * 4,           # links 1 2 3; pairs O A B slide
    "course_slider_crank": 3 * 3 - 2 * 4,    # links 1 2 3; pairs O A B slide
    "slider_crank_vertical": 3 * 3 - 2 * 4,  # links 1 2 3; pairs O A B slide
    "scotch_yoke": 3 * 3 - 2 * 4,            # links 1 2 3; pairs O A slot rail
    "slotted_link": 3 * 3 - 2 * 4,           # links 1 2 3; pairs O1 A slot O3
    "six_bar": 3 * 5 - 2 * 7,                # links 1..5; pairs O A B C D F slide
    "slotted_link_two_dyad": 3 * 5 - 2 * 7,  # links 1..5; pairs O1 A slot_A O3 slot_B B ram
    "six_bar_class3": 3 * 5 - 2 * 7,         # links 1..5; pairs O A B C D E F
    "watt_six_bar": 3 * 5 - 2 * 7,           # links 1..5; seven revolute pairs
    "stephenson_six_bar": 3 * 5 - 2 * 7,     # links 1..5; seven revolute pairs
    "five_bar_two_input": 3 * 4 - 2 * 5,     # links 1..4; pairs O A B D Q
    "piston_driven_crank": 3 * 3 - 2 * 4,    # links 1 2 3; pairs O A B slide
    "cylinder_boom": 3 * 3 - 2 * 4,          # links 1 2 3; pairs O C B K
}

#: structural formulas derived by hand from the scheme files (docs/methods.md#structure)
HAND_FORMULA = {
    "four_bar": "I(0,1) → II-RRR(2,3)",
    "flying_shears": "I(0,1) → II-RRR(2,3)",
    "slider_crank": "I(0,1) → II-RRP(2,3)",              # rod 2: R A, R B; slider 3: P on frame
    "slider_crank_vertical": "I(0,1) → II-RRP(2,3)",
    "scotch_yoke": "I(0,1) → II-RPP(2,3)",               # block 2: R A, P in slot; yoke 3: P rail
    "slotted_link": "I(0,1) → II-RPR(2,3)",              # block 2: R A, P slot; rocker 3: R O3
    "six_bar": "I(0,1) → II-RRR(2,3) → II-RRP(4,5)",
    "course_slider_crank": "I(0,1) → II-RRP(2,3)",
    "slotted_link_two_dyad": "I(0,1) → II-RPR(2,3) → II-PRP(4,5)",
    # legs 2 (A, B), 4 (C, E), 5 (D, F) on the ternary link 3 (B, C, D): no two links form a dyad
    "six_bar_class3": "I(0,1) → III(2,3,4,5)",
    # a crank-rocker (2, 3) first; its plate drives the second dyad (4, 5)
    "watt_six_bar": "I(0,1) → II-RRR(2,3) → II-RRR(4,5)",
    "stephenson_six_bar": "I(0,1) → II-RRR(2,3) → II-RRR(4,5)",
    # cranks 1 (O, A) and 4 (Q, D) on the frame; couplers 2 (A, B) and 3 (D, B) meet at B
    "five_bar_two_input": "I(0,1) → I(0,4) → II-RRR(2,3)",
    # the piston 3 is driven along the frame's guide (class I with the frame); crank 1 and rod 2
    # meet at A: a dyad with its outer pairs O (frame) and B (piston)
    "piston_driven_crank": "I(0,3) → II-RRR(1,2)",
    # the cylinder K drives the slide between barrel 2 and rod 3: with it given, boom 1, barrel 2
    # and rod 3 have 9 unknowns and 9 equations (O, C, B: 2 each; K: 3), no subset closed
    "cylinder_boom": "I(K) → II(1,2,3)",
}


@pytest.mark.parametrize("name", sorted(HAND_MOBILITY))
def test_mobility_by_hand(name):
    assert HAND_MOBILITY[name] == len(linkage.load(name).inputs)
    assert linkage.mobility(linkage.load(name)) == HAND_MOBILITY[name]


@pytest.mark.parametrize("name", SHIPPED)
def test_mobility_counted_from_the_file(name):
    """W from the raw TOML (every link but the frame, every pair) equals the library's and the inputs."""
    data = tomllib.loads((SCHEMES_DIR / f"{name}.toml").read_text(encoding="utf-8"))
    frame = data.get("frame", "0")
    n = len([k for k in data["links"] if k != frame])
    p = len(data["pairs"])
    inputs = data.get("inputs", data.get("input"))
    inputs = [inputs] if isinstance(inputs, str) else inputs
    mech = linkage.load(name)
    assert linkage.mobility(mech) == 3 * n - 2 * p == len(inputs)


@pytest.mark.parametrize("name", sorted(HAND_FORMULA))
def test_formula_by_hand(name):
    assert linkage.decompose(linkage.load(name)).formula == HAND_FORMULA[name]


def test_every_shipped_scheme_has_a_hand_formula():
    missing = set(SHIPPED) - (set(HAND_FORMULA) & set(HAND_MOBILITY))
    assert not missing, f"add the hand-derived W and formula of {sorted(missing)}"


# ----------------------------------------------------------------------------------------------
# builder-made mechanisms
# ----------------------------------------------------------------------------------------------


def four_bar_builder(name="four_bar", *, pair_c=True, inputs=("1",), frame_points=None) -> MechanismBuilder:
    """The shipped four-bar (coupler point E) by builder calls; more frame points on request."""
    b = MechanismBuilder(name)
    b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0), **(frame_points or {})})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "B"), length=0.3, points={"E": {"from": "A", "distance": 0.15, "angle_deg": 30}})
    b.link("3", line=("C", "B"), length=0.25)
    b.revolute("O", "0", "1").revolute("A", "1", "2").revolute("B", "2", "3")
    if pair_c:
        b.revolute("C", "3", "0")
    b.inputs(*inputs).assembly("B", left_of=("A", "C"))
    return b


def test_five_bar_two_inputs():
    # n = 4 (1 2 3 4), p = 5 (O A B C E): W = 3*4 - 2*5 = 2, two cranks 1 and 4
    b = MechanismBuilder("five_bar")
    b.link("0", points={"O": (0.0, 0.0), "E": (0.4, 0.0)})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "B"), length=0.35)
    b.link("3", line=("C", "B"), length=0.3)
    b.link("4", line=("E", "C"), length=0.12)
    for pair, x, y in [("O", "0", "1"), ("A", "1", "2"), ("B", "2", "3"), ("C", "3", "4"), ("E", "4", "0")]:
        b.revolute(pair, x, y)
    b.inputs("1", "4").assembly("B", left_of=("A", "C"))
    with pytest.raises(SchemeError, match="input link '4' needs a law"):
        b.build()        # how the second crank turns with the first must be declared
    mech = b.input_law("4", ratio=1.0).build()
    assert linkage.mobility(mech) == 3 * 4 - 2 * 5
    assert linkage.decompose(mech).formula == "I(0,1) → I(0,4) → II-RRR(2,3)"
    assert linkage.analyze(mech, [0.3]).status.tolist() == [0]


def six_bar_renamed(order: list[int] | None = None) -> MechanismBuilder:
    """The shipped six_bar with links renamed so that sorted names do not follow the groups:
    crank "k", coupler "c", rocker "d", rod "a", slider "b". ``order`` permutes the calls."""
    calls = [
        lambda b: b.link("0", points={"O": (0.0, 0.0), "C": (0.3, 0.0)},
                         guides={"slide": {"through": (0.0, 0.3), "angle_deg": 0}}),
        lambda b: b.link("k", line=("O", "A"), length=0.1),
        lambda b: b.link("c", line=("A", "B"), length=0.3),
        lambda b: b.link("d", line=("C", "B"), length=0.25, points={"D": {"from": "C", "distance": 0.35}}),
        lambda b: b.link("a", line=("D", "F"), length=0.4),
        lambda b: b.link("b", points={"F": (0.0, 0.0)}),
        lambda b: b.revolute("O", "0", "k"),
        lambda b: b.revolute("A", "k", "c"),
        lambda b: b.revolute("B", "c", "d"),
        lambda b: b.revolute("C", "d", "0"),
        lambda b: b.revolute("D", "d", "a"),
        lambda b: b.revolute("F", "a", "b"),
        lambda b: b.prismatic("slide", "0", "b", guide="slide", at="F"),
        lambda b: b.inputs("k"),
        lambda b: b.assembly("B", left_of=("A", "C")),
        lambda b: b.assembly("F", towards=0.0, origin="D"),
    ]
    b = MechanismBuilder("six_bar_renamed")
    for i in order if order is not None else range(len(calls)):
        calls[i](b)
    return b


def test_group_order_follows_structure_not_names():
    """The rod-slider dyad (a, b) sorts first by name but hangs on the rocker d: it comes second."""
    mech = six_bar_renamed().build()
    assert linkage.mobility(mech) == 3 * 5 - 2 * 7
    assert linkage.decompose(mech).formula == "I(0,k) → II-RRR(c,d) → II-RRP(a,b)"


def test_renamed_six_bar_moves_like_the_shipped_one():
    shipped = linkage.analyze(linkage.load("six_bar"), PHI)
    renamed = linkage.analyze(six_bar_renamed().build(), PHI)
    for point in "OABCDF":
        np.testing.assert_allclose(renamed.point(point), shipped.point(point), rtol=0, atol=1e-14)
        for mine, theirs in zip(renamed.point_analogs(point), shipped.point_analogs(point)):
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-13)


def test_prr_is_rrp_with_links_in_kind_order():
    """A slider-crank whose slider is named before its rod: PRR = RRP, the rod listed first."""
    b = MechanismBuilder("prr")
    b.link("0", points={"O": (0.0, 0.0)}, guides={"g": {"through": (0.0, 0.0), "angle": 0.0}})
    b.link("1", line=("O", "A"), length=0.05)
    b.link("2", points={"B": (0.0, 0.0)})                 # slider
    b.link("3", line=("A", "B"), length=0.2)              # rod
    b.revolute("O", "0", "1").revolute("A", "1", "3").revolute("B", "3", "2")
    b.prismatic("g", "0", "2", guide="g", at="B")
    mech = b.inputs("1").assembly("B", towards=0.0, origin="O").build()
    assert linkage.decompose(mech).formula == "I(0,1) → II-RRP(3,2)"


# ----------------------------------------------------------------------------------------------
# errors
# ----------------------------------------------------------------------------------------------


def test_mobility_mismatch_missing_pair():
    mech = four_bar_builder(pair_c=False).build()      # the builder does not check mobility
    w = 3 * 3 - 2 * 3
    assert linkage.mobility(mech) == w == 3
    with pytest.raises(StructureError, match=rf"four_bar.*W.*= {w}\b.*1 input.*'1'"):
        linkage.decompose(mech)


def test_mobility_mismatch_two_inputs():
    mech = four_bar_builder(inputs=("1", "3")).input_law("3", ratio=1.0).build()
    with pytest.raises(StructureError, match=r"four_bar.*W.*= 1\b.*2 input.*'1', '3'"):
        linkage.decompose(mech)


def test_mobility_mismatch_names_the_links():
    """docs/methods.md#structure: "W != number of inputs is an error that names the links involved"."""
    b = four_bar_builder()
    b.link("4", line=("E", "F"), length=0.1)
    b.revolute("E", "2", "4")
    mech = b.build()
    assert linkage.mobility(mech) == 3 * 4 - 2 * 5
    with pytest.raises(StructureError) as info:
        linkage.decompose(mech)
    message = str(info.value)
    missing = [k for k in ("1", "2", "3", "4") if f"'{k}'" not in message]
    assert not missing, f"moving links {missing} are not named in: {message}"


NOT_DECOMPOSABLE = """\
name = "locked_and_loose"
input = "1"

[links.0]
points = { O = [0.0, 0.0], C = [0.3, 0.0], D = [0.5, 0.0], G = [0.6, 0.0] }

[links.1]
line = ["O", "A"]
length = 0.1

[links.2]
line = ["A", "B"]
length = 0.3

[links.3]
line = ["C", "B"]
length = 0.25

[links.4]                 # pinned to the frame twice: over-constrained
line = ["D", "G"]
length = 0.1
points.H = [0.05, 0.05]

[links.5]                 # hangs on link 4 only: free to turn
line = ["H", "K"]
length = 0.1

[pairs.O]
links = ["0", "1"]
[pairs.A]
links = ["1", "2"]
[pairs.B]
links = ["2", "3"]
[pairs.C]
links = ["3", "0"]
[pairs.D]
links = ["4", "0"]
[pairs.G]
links = ["4", "0"]
[pairs.H]
links = ["4", "5"]

[assembly.B]
left_of = ["A", "C"]
"""


def test_not_decomposable_from_file(tmp_path):
    # n = 5, p = 7: W = 3*5 - 2*7 = 1 = inputs, yet links 4 and 5 form no Assur group
    data = tomllib.loads(NOT_DECOMPOSABLE)
    assert 3 * (len(data["links"]) - 1) - 2 * len(data["pairs"]) == 1
    path = tmp_path / "locked_and_loose.toml"
    path.write_text(NOT_DECOMPOSABLE, encoding="utf-8")
    with pytest.raises(SchemeError, match=re.escape(str(path)) + r".*links \['4', '5'\]"):
        linkage.load(path)


def test_not_decomposable_structure_error():
    b = four_bar_builder("locked_and_loose", frame_points={"D": (0.5, 0.0), "G": (0.6, 0.0)})
    b.link("4", line=("D", "G"), length=0.1, points={"H": (0.05, 0.05)})
    b.link("5", line=("H", "K"), length=0.1)
    b.revolute("D", "4", "0").revolute("G", "4", "0").revolute("H", "4", "5")
    mech = b.build()
    assert linkage.mobility(mech) == 3 * 5 - 2 * 7 == 1
    with pytest.raises(StructureError, match=r"locked_and_loose.*links \['4', '5'\]"):
        linkage.decompose(mech)


def test_class_three_group_is_decomposed_and_written_in_the_formula():
    """A crank driving a triad (ternary link T, binary links 2, 3, 4): one class-III group,
    whatever the order of declaration."""
    b = MechanismBuilder("triad")
    b.link("0", points={"O": (0.0, 0.0), "D": (0.5, 0.0), "G": (0.25, 0.5)})
    b.link("1", line=("O", "A"), length=0.1)
    b.link("2", line=("A", "P"), length=0.3)
    b.link("3", line=("D", "Q"), length=0.3)
    b.link("4", line=("G", "R"), length=0.2)
    b.link("T", points={"P": (0.0, 0.0), "Q": (0.2, 0.0), "R": (0.1, 0.15)})
    for pair, x, y in [("O", "0", "1"), ("A", "1", "2"), ("D", "0", "3"), ("G", "0", "4"),
                       ("P", "2", "T"), ("Q", "3", "T"), ("R", "4", "T")]:
        b.revolute(pair, x, y)
    mech = b.inputs("1").build()
    assert linkage.mobility(mech) == 3 * 5 - 2 * 7 == 1
    structure = linkage.decompose(mech)
    assert structure.formula == "I(0,1) → III(2,3,4,T)"
    assert structure.groups[0].group_class == "III" and structure.groups[0].kind == "RRR-RRR"


# ----------------------------------------------------------------------------------------------
# declaration order
# ----------------------------------------------------------------------------------------------


def toml_sections(text: str) -> tuple[str, list[str]]:
    """(top-level part, [sections]) of a scheme text; each section runs to the next header."""
    lines = text.splitlines(keepends=True)
    heads = [i for i, line in enumerate(lines) if line.startswith("[")]
    top = "".join(lines[: heads[0]])
    sections = ["".join(lines[a:b]) for a, b in zip(heads, heads[1:] + [len(lines)])]
    return top, [s if s.endswith("\n") else s + "\n" for s in sections]


def assert_same_motion(a: linkage.Motion, b: linkage.Motion) -> None:
    ca, cb = a.columns(), b.columns()
    assert list(ca) == list(cb)
    for key in ca:
        np.testing.assert_array_equal(ca[key], cb[key], err_msg=key)


@pytest.mark.parametrize("name", SHIPPED)
def test_toml_section_order_does_not_matter(name):
    text = (SCHEMES_DIR / f"{name}.toml").read_text(encoding="utf-8")
    top, sections = toml_sections(text)
    reference = linkage.loads(text)
    formula = linkage.decompose(reference).formula
    motion = linkage.analyze(reference, positions(reference))
    rng = random.Random(20240601)
    orders = set()
    for _ in range(4):
        shuffled = sections[:]
        rng.shuffle(shuffled)
        mech = linkage.loads(top + "".join(shuffled))
        orders.add((tuple(mech.links), tuple(mech.pairs)))
        assert (mech.links, mech.pairs, mech.inputs) == (reference.links, reference.pairs, reference.inputs)
        assert linkage.decompose(mech).formula == formula
        assert_same_motion(linkage.analyze(mech, positions(mech)), motion)
    assert len(orders) > 1, "the permutations did not change the declaration order"


def test_assembly_order_does_not_change_equality():
    """TOML tables are unordered: [assembly.F] before [assembly.B] declares the same mechanism."""
    text = (SCHEMES_DIR / "six_bar.toml").read_text(encoding="utf-8")
    top, sections = toml_sections(text)
    heads = [s.splitlines()[0].split("#")[0].strip() for s in sections]
    b, f = heads.index("[assembly.B]"), heads.index("[assembly.F]")
    sections[b], sections[f] = sections[f], sections[b]
    assert linkage.loads(top + "".join(sections)) == linkage.loads(text)


def test_builder_call_order_does_not_matter():
    reference = six_bar_renamed().build()
    motion = linkage.analyze(reference, PHI)
    rng = random.Random(7)
    for _ in range(5):
        order = list(range(16))
        rng.shuffle(order)
        mech = six_bar_renamed(order).build()
        assert (mech.links, mech.pairs, mech.inputs) == (reference.links, reference.pairs, reference.inputs)
        assert linkage.decompose(mech).formula == "I(0,k) → II-RRR(c,d) → II-RRP(a,b)"
        assert_same_motion(linkage.analyze(mech, PHI), motion)


# ----------------------------------------------------------------------------------------------
# mirror and scale
# ----------------------------------------------------------------------------------------------


def kinematic_data(mech: linkage.Mechanism) -> dict:
    """The scheme as plain data without the extra sections (loads ...): kinematics only."""
    data = copy.deepcopy(to_dict(mech))
    for key in mech.extra:
        data.pop(key, None)
    return data


def mirrored(mech: linkage.Mechanism) -> linkage.Mechanism:
    """The mirror image in the y axis (x -> -x).

    The frame's points are global: ``(x, y) -> (-x, y)``, guide angles ``a -> pi - a``. A moving
    link keeps its pose convention with ``theta -> pi - theta``: since ``M Rot(theta) p =
    Rot(pi - theta) (p_x, -p_y)`` with ``M = diag(-1, 1)``, its local points become
    ``(x, -y)`` and its guide angles ``a -> -a``. Either way a guide direction ``u`` becomes
    ``M u``. A prismatic pair's angle ``g`` (slider x axis relative to the guide direction,
    ``theta_slider - theta_guide_link = a + g``) becomes ``-g``, or ``pi - g`` when the frame is
    the slider (its angle stays 0 instead of becoming pi). Left and right swap; a ``towards``
    direction ``a`` becomes ``pi - a``. A further input's law ``theta = r phi + p`` becomes, with
    ``phi -> pi - phi`` and ``theta -> pi - theta``, ``theta = r phi + (pi - r pi - p)``; a table's
    points ``(phi, theta)`` become ``(pi - phi, pi - theta)`` in reverse order.
    """
    data = kinematic_data(mech)
    for law in data.get("input_laws", {}).values():
        if "table" in law:
            law["table"] = [[math.pi - a, math.pi - b] for a, b in reversed(law["table"])]
        else:
            law["phase"] = math.pi - law["ratio"] * math.pi - law["phase"]
    frame = data["frame"]
    for name, spec in data["links"].items():
        if name == frame:
            flip, turn = (lambda v: [-v[0], v[1]]), (lambda a: math.pi - a)
        else:
            flip, turn = (lambda v: [v[0], -v[1]]), (lambda a: -a)
        spec["points"] = {p: flip(v) for p, v in spec["points"].items()}
        spec["com"] = flip(spec["com"])
        for guide in spec.get("guides", {}).values():
            guide["through"] = flip(guide["through"])
            guide["angle"] = turn(guide["angle"])
    for pair in data["pairs"].values():
        if pair["kind"] == "P":
            pair["angle"] = math.pi - pair["angle"] if pair["links"][1] == frame else -pair["angle"]
    for rule in data.get("assembly", {}).values():
        if "left_of" in rule:
            rule["right_of"] = rule.pop("left_of")
        elif "right_of" in rule:
            rule["left_of"] = rule.pop("right_of")
        elif "towards" in rule:
            rule["towards"] = math.pi - rule["towards"]
        else:
            pytest.skip("a raw branch sign has no kind-independent mirror image")
    return from_dict(data)


def scaled(mech: linkage.Mechanism, k: float) -> linkage.Mechanism:
    """Every length times ``k`` (angles unchanged)."""
    data = kinematic_data(mech)
    for spec in data["links"].values():
        spec["points"] = {p: [k * v[0], k * v[1]] for p, v in spec["points"].items()}
        spec["com"] = [k * c for c in spec["com"]]
        spec["inertia"] = k * k * spec["inertia"]
        for guide in spec.get("guides", {}).values():
            guide["through"] = [k * c for c in guide["through"]]
    if "range" in data and not mech.coordinate.is_angle:    # a slide input's stroke, m
        data["range"] = [k * v for v in data["range"]]
    return from_dict(data)


def inclined_slider_crank() -> linkage.Mechanism:
    """Guide at 20 deg off the frame's x axis, slider turned 30 deg on it, a slider point K off
    the guide: every angle of a prismatic pair on the frame is non-zero."""
    b = MechanismBuilder("inclined_slider_crank")
    b.link("0", points={"O": (0.0, 0.0)},
           guides={"g": {"through": (0.02, 0.01), "angle_deg": 20, "offset": 0.005}})
    b.link("1", line=("O", "A"), length=0.07)
    b.link("2", line=("A", "B"), length=0.25, points={"S": {"from": "A", "distance": 0.1, "angle_deg": 15}})
    b.link("3", points={"B": (0.0, 0.0), "K": (0.03, 0.02)})
    b.revolute("O", "0", "1").revolute("A", "1", "2").revolute("B", "2", "3")
    b.prismatic("g", "0", "3", guide="g", at="B", angle=math.radians(30))
    return b.inputs("1").assembly("B", towards=math.radians(20), origin="O").build()


def skewed_slotted_link() -> linkage.Mechanism:
    """Slotted link whose slot is turned 5 deg and offset 0.01 m on the rocker, the block turned
    15 deg in it and carrying a point W: the angles of a prismatic pair between moving links."""
    b = MechanismBuilder("skewed_slotted_link")
    b.link("0", points={"O1": (0.0, 0.12), "O3": (0.0, 0.0)})
    b.link("1", line=("O1", "A"), length=0.076)
    b.link("2", points={"A": (0.0, 0.0), "W": (0.02, 0.01)})
    b.link("3", line=("O3", "C"), length=0.5,
           guides={"slot": {"through": "O3", "angle_deg": 5, "offset": 0.01}})
    b.revolute("O1", "0", "1").revolute("A", "1", "2").revolute("O3", "3", "0")
    b.prismatic("slot", "3", "2", guide="slot", at="A", angle=math.radians(15))
    return b.inputs("1").assembly("C", towards=math.pi / 2, origin="O3").build()


BUILT = {"inclined_slider_crank": inclined_slider_crank, "skewed_slotted_link": skewed_slotted_link}


def mechanism(name: str) -> linkage.Mechanism:
    return BUILT[name]() if name in BUILT else linkage.load(name)


def test_built_mechanisms():
    assert linkage.decompose(inclined_slider_crank()).formula == "I(0,1) → II-RRP(2,3)"
    assert linkage.decompose(skewed_slotted_link()).formula == "I(0,1) → II-RPR(2,3)"


def wrapped(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def quantities(mech: linkage.Mechanism):
    """(points, link angle quantities, slide quantities) of a mechanism."""
    links = [f"{k}.theta" for k in mech.moving_links]
    slides = [f"{k}.s" for k, p in sorted(mech.pairs.items()) if p.kind == "P"]
    return mech.point_names, links, slides


@pytest.mark.parametrize("name", SHIPPED + sorted(BUILT))
def test_mirror_invariance(name):
    """Mirrored at pi - phi: P = (-x, y), P' = (x', -y'), P'' = (-x'', y''); theta = pi - theta,
    theta' = theta', theta'' = -theta''; s = s, s' = -s', s'' = s'' (d/d(pi - phi) = -d/dphi).

    A slide input's coordinate is a slide, which the mirror keeps (``s = u . d`` with ``u`` and
    ``d`` both mirrored): at the same s, P = (-x, y), P' = (-x', y'), P'' = (-x'', y''); theta =
    pi - theta, theta' = -theta', theta'' = -theta''; s, s', s'' unchanged."""
    mech = mechanism(name)
    mirror = mirrored(mech)
    assert linkage.decompose(mirror).formula == linkage.decompose(mech).formula
    size = mech.size
    at = positions(mech)
    crank = mech.coordinate.is_angle
    orig = linkage.analyze(mech, at)
    image = linkage.analyze(mirror, np.pi - at if crank else at)
    points, links, slides = quantities(mech)
    flip_x, flip_y = np.array([-1.0, 1.0]), np.array([1.0, -1.0])
    sign = 1.0 if crank else -1.0   # d/d(pi - phi) = -d/dphi; d/ds unchanged
    # analogs per m of a slide input are dimensionless (points) or per m (angles)
    scale1 = 1.0 if crank else 1.0 / size
    for p in points:
        (d1, d2), (e1, e2) = orig.point_analogs(p), image.point_analogs(p)
        np.testing.assert_allclose(image.point(p), orig.point(p) * flip_x, rtol=0, atol=1e-12 * size, err_msg=p)
        np.testing.assert_allclose(e1, sign * d1 * flip_y, rtol=0, atol=1e-12 * size * scale1, err_msg=p + "'")
        np.testing.assert_allclose(e2, d2 * flip_x, rtol=0, atol=1e-12 * size * scale1**2, err_msg=p + "''")
    for q in links:
        (t, t1, t2), (u, u1, u2) = orig.quantity(q), image.quantity(q)
        np.testing.assert_allclose(wrapped(u - (np.pi - t)), 0.0, rtol=0, atol=1e-12, err_msg=q)
        np.testing.assert_allclose(u1, sign * t1, rtol=1e-12, atol=1e-12 * scale1, err_msg=q + "'")
        np.testing.assert_allclose(u2, -t2, rtol=1e-12, atol=1e-12 * scale1**2, err_msg=q + "''")
    for q in slides:
        (s, s1, s2), (r, r1, r2) = orig.quantity(q), image.quantity(q)
        np.testing.assert_allclose(r, s, rtol=0, atol=1e-12 * size, err_msg=q)
        np.testing.assert_allclose(r1, -sign * s1, rtol=0, atol=1e-12 * size * scale1, err_msg=q + "'")
        np.testing.assert_allclose(r2, s2, rtol=0, atol=1e-12 * size * scale1**2, err_msg=q + "''")


@pytest.mark.parametrize("k", [1e-3, 1e3, 1e-6, 1e6])
@pytest.mark.parametrize("name", SHIPPED + sorted(BUILT))
def test_scale_invariance(name, k):
    """Lengths x k: positions, point and slide analogs x k; link angles and their analogs equal.

    A slide input's stroke is a length too (scaled with the rest) and so is its coordinate: at
    the slide k s, the analogs per m of order n scale as k^(1 - n) for points and slides and
    k^(-n) for angles (d/d(k s) = d/ds / k)."""
    mech = mechanism(name)
    big = scaled(mech, k)
    assert big.size == pytest.approx(k * mech.size, rel=1e-15)
    assert linkage.decompose(big).formula == linkage.decompose(mech).formula
    crank = mech.coordinate.is_angle
    if not crank:
        assert big.input_range == pytest.approx(tuple(k * v for v in mech.input_range), rel=1e-15)
    at = positions(mech)
    ref = linkage.analyze(mech, at)
    out = linkage.analyze(big, at if crank else k * at)
    points, links, slides = quantities(mech)
    per = 1.0 if crank else k   # the coordinate scales by this
    tol = 1e-12 * k * mech.size  # 1e-12 relative to the (scaled) size of the mechanism
    for p in points:
        np.testing.assert_allclose(out.point(p), k * ref.point(p), rtol=1e-12, atol=tol, err_msg=p)
        for order, (mine, theirs) in enumerate(zip(out.point_analogs(p), ref.point_analogs(p)), 1):
            np.testing.assert_allclose(mine, k * theirs / per**order, rtol=1e-12, atol=tol / per**order,
                                       err_msg=p + "'" * order)
    for q in links:
        (t, t1, t2), (u, u1, u2) = ref.quantity(q), out.quantity(q)
        np.testing.assert_allclose(wrapped(u - t), 0.0, rtol=0, atol=1e-12, err_msg=q)
        np.testing.assert_allclose(u1, t1 / per, rtol=1e-12, atol=1e-12 / per, err_msg=q + "'")
        np.testing.assert_allclose(u2, t2 / per**2, rtol=1e-12, atol=1e-12 / per**2, err_msg=q + "''")
    for q in slides:
        (s, s1, s2), (r, r1, r2) = ref.quantity(q), out.quantity(q)
        np.testing.assert_allclose(r, k * s, rtol=1e-12, atol=tol, err_msg=q)
        np.testing.assert_allclose(r1, k * s1 / per, rtol=1e-12, atol=tol / per, err_msg=q + "'")
        np.testing.assert_allclose(r2, k * s2 / per**2, rtol=1e-12, atol=tol / per**2, err_msg=q + "''")


def test_the_subset_masks_choose_the_group_the_set_by_set_search_chooses(monkeypatch):
    """``group_links`` counts every subset of up to MASK_LINKS unknown links at once; the set by
    set search (combinations, the rule's own statement) must pick the same group at every step of
    every 8-link mechanism of the synthesis (groups of 2 to 6 links) and of every shipped scheme
    (driven pairs and prismatic pairs among them)."""
    import linkage.structure as S
    from assur import RevoluteJoint
    from linkage.research.synthesis import mechanisms

    def both(unknown, known, joints, used):
        fast = S.group_links(unknown, known, joints, used)
        monkeypatch.setattr(S, "MASK_LINKS", -1)
        slow = S.group_links(unknown, known, joints, used)
        monkeypatch.setattr(S, "MASK_LINKS", 16)
        assert fast == slow, (unknown, sorted(known), fast, slow)
        return fast

    steps = 0
    for t in mechanisms(8):
        pairs = list(t.pairs)       # (pair, link, link)
        joints = {p: RevoluteJoint(p, a, b, (0.0, 0.0), (0.0, 0.0)) for p, a, b in pairs}
        known = {"0", "1"}
        used = {p for p, a, b in pairs if {a, b} == known}
        unknown = sorted({x for _, a, b in pairs for x in (a, b)} - known)
        while unknown:
            group = both(unknown, known, joints, used)
            assert group is not None
            steps += 1
            known |= set(group)
            used |= {p for p, a, b in pairs if a in known and b in known}
            unknown = [k for k in unknown if k not in known]
    assert steps > 153
    for name in linkage.shipped_schemes():
        mech = linkage.load(name)
        monkeypatch.setattr(S, "MASK_LINKS", -1)
        slow = S.decompose(mech).formula
        monkeypatch.setattr(S, "MASK_LINKS", 16)
        assert S.decompose(mech).formula == slow, name
