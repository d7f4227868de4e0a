"""Every bad scheme declaration raises one :class:`linkage.SchemeError` whose message names the
file, the entry and the offending value (every problem at once); every shipped scheme round-trips through TOML.

The bad schemes are small edits of the four-bar and slider-crank texts below, written to
``tmp_path`` under a distinctive file name so that the message can be checked for it.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

import linkage
from linkage import MechanismBuilder, SchemeError

SCHEMES_DIR = Path(__file__).resolve().parent.parent / "schemes"

FOUR_BAR = """\
name = "four_bar"
input = "1"
output = "3.theta"

[links.0]
points = { O = [0.0, 0.0], C = [0.3, 0.0] }

[links.1]
line = ["O", "A"]
length = 0.1

[links.2]
line = ["A", "B"]
length = 0.3
points.E = { from = "A", distance = 0.15, angle_deg = 30 }

[links.3]
line = ["C", "B"]
length = 0.25

[pairs.O]
links = ["0", "1"]

[pairs.A]
links = ["1", "2"]

[pairs.B]
links = ["2", "3"]

[pairs.C]
links = ["3", "0"]

[assembly.B]
left_of = ["A", "C"]
"""

SLIDER_CRANK = """\
name = "slider_crank"
input = "1"
output = "B.x"

[links.0]
points = { O = [0.0, 0.0] }
guides.slide = { through = [0.0, 0.01], angle_deg = 0 }

[links.1]
line = ["O", "A"]
length = 0.07

[links.2]
line = ["A", "B"]
length = 0.22

[links.3]
points.B = [0.0, 0.0]

[pairs.O]
links = ["0", "1"]

[pairs.A]
links = ["1", "2"]

[pairs.B]
links = ["2", "3"]

[pairs.slide]
kind = "P"
links = ["0", "3"]
guide = "slide"
at = "B"

[assembly.B]
from = "O"
towards_deg = 0
"""


def edit(text: str, old: str, new: str) -> str:
    """``text`` with the one occurrence of ``old`` replaced (fails loudly on a stale edit)."""
    assert text.count(old) == 1, f"edit target {old!r} occurs {text.count(old)} times"
    return text.replace(old, new)


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def names(path, *parts: str) -> str:
    """Regex: one line of the message that starts with the file and contains ``parts`` in order."""
    return "(?m)^" + re.escape(str(path)) + ".*" + ".*".join(re.escape(p) for p in parts)


def test_base_texts_are_valid(tmp_path):
    """The texts every bad scheme is edited from load cleanly (so each error is the edit's)."""
    assert linkage.load(write(tmp_path, "four.toml", FOUR_BAR)).name == "four_bar"
    assert linkage.load(write(tmp_path, "slider.toml", SLIDER_CRANK)).name == "slider_crank"


# ----------------------------------------------------------------------------------------------
# links and pairs
# ----------------------------------------------------------------------------------------------


def test_pair_joins_unknown_link(tmp_path):
    path = write(tmp_path, "unknown_link.toml",
                 edit(FOUR_BAR, 'links = ["2", "3"]', 'links = ["2", "L7"]'))
    with pytest.raises(SchemeError, match=names(path, "pair 'B'", "unknown link 'L7'")):
        linkage.load(path)


def test_point_declared_twice_via_line_and_points(tmp_path):
    text = edit(FOUR_BAR, 'line = ["O", "A"]\nlength = 0.1\n',
                'line = ["O", "A"]\nlength = 0.1\npoints.A = [0.1, 0.0]\n')
    path = write(tmp_path, "point_twice.toml", text)
    with pytest.raises(SchemeError, match=names(path, "link '1'", "point 'A'", "declared twice")):
        linkage.load(path)


def test_same_name_for_link_and_pair(tmp_path):
    # the pair C is renamed "3", the name of the rocker
    path = write(tmp_path, "name_clash.toml", edit(FOUR_BAR, "[pairs.C]\nlinks", '[pairs.3]\nat = "C"\nlinks'))
    with pytest.raises(SchemeError, match=names(path, "'3'", "link", "pair")):
        linkage.load(path)


def test_toml_table_declared_twice(tmp_path):
    text = FOUR_BAR + '\n[links.2]\nline = ["A", "B"]\nlength = 0.3\n'
    line = text.splitlines().index("[links.2]", text.splitlines().index("[links.2]") + 1) + 1
    path = write(tmp_path, "table_twice.toml", text)
    with pytest.raises(SchemeError, match=names(path, "links", "'2'", f"line {line}")):
        linkage.load(path)


def test_toml_key_declared_twice(tmp_path):
    """A key repeated inside a table: the message should name the key, not only the line."""
    text = edit(FOUR_BAR, "length = 0.25\n", "length = 0.25\nlength = 0.26\n")
    line = text.splitlines().index("length = 0.26") + 1
    path = write(tmp_path, "key_twice.toml", text)
    with pytest.raises(SchemeError, match=names(path, f"line {line}")):
        linkage.load(path)
    with pytest.raises(SchemeError, match=names(path, "length")):
        linkage.load(path)


def test_inline_key_declared_twice(tmp_path):
    text = edit(FOUR_BAR, "C = [0.3, 0.0] }", "C = [0.3, 0.0], O = [0.1, 0.0] }")
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "O = [0.1, 0.0]" in t)
    path = write(tmp_path, "inline_twice.toml", text)
    with pytest.raises(SchemeError, match=names(path, "'O'", f"line {line}")):
        linkage.load(path)


def test_builder_link_and_pair_declared_twice():
    b = MechanismBuilder("twice")
    b.link("0", points={"O": (0.0, 0.0)}).link("1", line=("O", "A"), length=0.1)
    b.link("1", line=("O", "A"), length=0.2)
    b.revolute("O", "0", "1").revolute("O", "0", "1").inputs("1")
    with pytest.raises(SchemeError) as info:
        b.build()
    problems = info.value.problems
    assert any(re.search(r"link '1'.*declared twice", p) for p in problems), problems
    assert any(re.search(r"pair 'O'.*declared twice", p) for p in problems), problems


@pytest.mark.parametrize("length", ["0", "0.0", "-0.3"])
def test_non_positive_length(tmp_path, length):
    path = write(tmp_path, "bad_length.toml", edit(FOUR_BAR, "length = 0.3\n", f"length = {length}\n"))
    with pytest.raises(SchemeError, match=names(path, "link '2'", "length", length)):
        linkage.load(path)


def test_missing_length(tmp_path):
    path = write(tmp_path, "no_length.toml", edit(FOUR_BAR, "length = 0.25\n", ""))
    with pytest.raises(SchemeError, match=names(path, "link '3'", "length", "None")):
        linkage.load(path)


def test_pair_joins_link_to_itself(tmp_path):
    path = write(tmp_path, "self_pair.toml", edit(FOUR_BAR, 'links = ["2", "3"]', 'links = ["2", "2"]'))
    with pytest.raises(SchemeError, match=names(path, "pair 'B'", "link '2'", "itself")):
        linkage.load(path)


def test_unknown_point_in_revolute_pair(tmp_path):
    text = edit(FOUR_BAR, '[pairs.B]\nlinks = ["2", "3"]', '[pairs.B]\nlinks = ["2", "3"]\nat = "Q"')
    path = write(tmp_path, "unknown_point.toml", text)
    with pytest.raises(SchemeError, match=names(path, "pair 'B'", "point 'Q'", "link '2'")):
        linkage.load(path)
    with pytest.raises(SchemeError, match=names(path, "pair 'B'", "point 'Q'", "link '3'")):
        linkage.load(path)


def test_point_missing_on_one_side_of_revolute_pair(tmp_path):
    # pair C pins 3 to the frame at E, a point of the coupler only
    text = edit(FOUR_BAR, '[pairs.C]\nlinks = ["3", "0"]', '[pairs.C]\nlinks = ["3", "0"]\nat = "E"')
    path = write(tmp_path, "point_one_side.toml", text)
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    bad = [p for p in info.value.problems if "pair 'C'" in p]
    assert len(bad) == 2, info.value.problems
    assert all(p.startswith(str(path)) and "'E'" in p for p in bad)


def test_unknown_guide_in_prismatic_pair(tmp_path):
    path = write(tmp_path, "unknown_guide.toml", edit(SLIDER_CRANK, 'guide = "slide"', 'guide = "track"'))
    with pytest.raises(SchemeError, match=names(path, "pair 'slide'", "link '0'", "guide 'track'", "slide")):
        linkage.load(path)


def test_unknown_slider_point_in_prismatic_pair(tmp_path):
    path = write(tmp_path, "unknown_slider_point.toml",
                 edit(SLIDER_CRANK, 'guide = "slide"\nat = "B"', 'guide = "slide"\nat = "Bx"'))
    with pytest.raises(SchemeError, match=names(path, "pair 'slide'", "point 'Bx'", "link '3'")):
        linkage.load(path)


def test_unknown_pair_kind(tmp_path):
    path = write(tmp_path, "bad_kind.toml", edit(SLIDER_CRANK, 'kind = "P"', 'kind = "cam"'))
    with pytest.raises(SchemeError, match=names(path, "pairs.slide", "kind", "'cam'")):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# unknown keys
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "old, new, entry, key",
    [
        ('input = "1"\n', 'input = "1"\ncolour = "red"\n', "top-level", "colour"),
        ("length = 0.1\n", "length = 0.1\nlenght = 0.1\n", "links.1", "lenght"),
        ('[pairs.A]\nlinks = ["1", "2"]', '[pairs.A]\nlinks = ["1", "2"]\npoint = "A"', "pairs.A", "point"),
        ('left_of = ["A", "C"]', 'left_of = ["A", "C"]\nleft = ["A", "C"]', "assembly.B", "left"),
        ("angle_deg = 30 }", "angle_deg = 30, dist = 1 }", "point 'E'", "dist"),
    ],
)
def test_unknown_keys(tmp_path, old, new, entry, key):
    path = write(tmp_path, "unknown_key.toml", edit(FOUR_BAR, old, new))
    with pytest.raises(SchemeError, match=names(path, entry, f"'{key}'")):
        linkage.load(path)


def test_unknown_key_in_guide(tmp_path):
    path = write(tmp_path, "guide_key.toml", edit(SLIDER_CRANK, "angle_deg = 0 }", "angle_deg = 0, slope = 1 }"))
    with pytest.raises(SchemeError, match=names(path, "link '0'", "guide 'slide'", "'slope'")):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# inputs and mobility
# ----------------------------------------------------------------------------------------------


def test_missing_input_link(tmp_path):
    path = write(tmp_path, "no_input.toml", edit(FOUR_BAR, 'input = "1"\n', ""))
    with pytest.raises(SchemeError, match=names(path, "input")):
        linkage.load(path)


def test_input_link_not_declared(tmp_path):
    path = write(tmp_path, "input_unknown.toml", edit(FOUR_BAR, 'input = "1"', 'input = "L9"'))
    with pytest.raises(SchemeError, match=names(path, "input link 'L9'")):
        linkage.load(path)


def test_input_link_not_pinned_to_frame(tmp_path):
    path = write(tmp_path, "input_floating.toml", edit(FOUR_BAR, 'input = "1"', 'input = "2"'))
    with pytest.raises(SchemeError, match=names(path, "input link '2'", "frame '0'")):
        linkage.load(path)


def test_input_link_is_the_frame(tmp_path):
    path = write(tmp_path, "input_frame.toml", edit(FOUR_BAR, 'input = "1"', 'input = "0"'))
    with pytest.raises(SchemeError, match=names(path, "input link '0'", "frame")):
        linkage.load(path)


FOUR_BAR_EXTRA_LINK = FOUR_BAR + """
[links.4]
line = ["E", "F"]
length = 0.1

[pairs.E]
links = ["2", "4"]
"""


def test_wrong_mobility_extra_link(tmp_path):
    # n = 4 moving links, p = 5 pairs: W = 3*4 - 2*5 = 2, but one input link
    w = 3 * 4 - 2 * 5
    path = write(tmp_path, "extra_link.toml", FOUR_BAR_EXTRA_LINK)
    with pytest.raises(SchemeError, match=names(path, "mobility", f"= {w}", "1 input", "'1'")):
        linkage.load(path)


def test_wrong_mobility_missing_pair(tmp_path):
    # n = 3, p = 3: W = 3*3 - 2*3 = 3
    w = 3 * 3 - 2 * 3
    path = write(tmp_path, "missing_pair.toml", edit(FOUR_BAR, '[pairs.C]\nlinks = ["3", "0"]\n', ""))
    with pytest.raises(SchemeError, match=names(path, "mobility", f"= {w}", "1 input")):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# assembly and output
# ----------------------------------------------------------------------------------------------


def test_assembly_unknown_point(tmp_path):
    path = write(tmp_path, "assembly_point.toml", edit(FOUR_BAR, 'left_of = ["A", "C"]', 'left_of = ["A", "Z"]'))
    with pytest.raises(SchemeError, match=names(path, "assembly of point 'B'", "unknown point 'Z'")):
        linkage.load(path)


def test_assembly_of_unknown_point(tmp_path):
    path = write(tmp_path, "assembly_of_unknown.toml", edit(FOUR_BAR, "[assembly.B]", "[assembly.Z]"))
    with pytest.raises(SchemeError, match=names(path, "assembly of point 'Z'", "unknown point 'Z'")):
        linkage.load(path)


def test_two_branches_without_condition(tmp_path):
    path = write(tmp_path, "no_assembly.toml", edit(FOUR_BAR, '[assembly.B]\nleft_of = ["A", "C"]\n', ""))
    with pytest.raises(SchemeError, match=names(path, "RRR(2,3)", "two assembly branches", "'B'")):
        linkage.load(path)


def test_assembly_condition_with_two_rules(tmp_path):
    path = write(tmp_path, "assembly_two_rules.toml",
                 edit(FOUR_BAR, 'left_of = ["A", "C"]', 'left_of = ["A", "C"]\nright_of = ["A", "C"]'))
    with pytest.raises(SchemeError, match=names(path, "assembly of point 'B'", "left_of", "right_of")):
        linkage.load(path)


def test_assembly_condition_that_does_not_pick_a_branch(tmp_path):
    # B left of the line A -> B is never true nor false on either branch
    path = write(tmp_path, "assembly_degenerate.toml",
                 edit(FOUR_BAR, 'left_of = ["A", "C"]', 'left_of = ["A", "B"]'))
    with pytest.raises(SchemeError, match=names(path, "assembly of point 'B'", "RRR(2,3)")):
        linkage.load(path)


def test_assembly_branch_value(tmp_path):
    path = write(tmp_path, "assembly_branch.toml", edit(FOUR_BAR, 'left_of = ["A", "C"]', "branch = 2"))
    with pytest.raises(SchemeError, match=names(path, "assembly of point 'B'", "branch", "2")):
        linkage.load(path)


@pytest.mark.parametrize("quantity", ["Z.x", "9.theta", "0.theta", "B.s", "B.z", "B"])
def test_output_quantity_does_not_exist(tmp_path, quantity):
    path = write(tmp_path, "bad_output.toml", edit(FOUR_BAR, 'output = "3.theta"', f'output = "{quantity}"'))
    with pytest.raises(SchemeError, match=names(path, f"output '{quantity}'")):
        linkage.load(path)


def test_output_start(tmp_path):
    path = write(tmp_path, "bad_start.toml", edit(
        FOUR_BAR, 'output = "3.theta"', 'output = { quantity = "3.theta", start = "middle" }'))
    with pytest.raises(SchemeError, match=names(path, "output '3.theta'", "start", "'middle'")):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# files
# ----------------------------------------------------------------------------------------------


def test_malformed_toml_has_line_number(tmp_path):
    text = edit(FOUR_BAR, "length = 0.3\n", "length = \n")
    line = text.splitlines().index("length = ") + 1
    path = write(tmp_path, "malformed.toml", text)
    with pytest.raises(SchemeError, match=names(path, "TOML", f"line {line}")):
        linkage.load(path)


def test_malformed_toml_unclosed_table_header(tmp_path):
    text = edit(FOUR_BAR, "[links.3]\n", "[links.3\n")
    line = text.splitlines().index("[links.3") + 1
    path = write(tmp_path, "malformed_header.toml", text)
    with pytest.raises(SchemeError, match=names(path, "TOML", f"line {line}")):
        linkage.load(path)


def test_loads_names_its_source():
    text = edit(FOUR_BAR, 'links = ["2", "3"]', 'links = ["2", "L7"]')
    with pytest.raises(SchemeError, match=names("my-scheme", "pair 'B'", "'L7'")):
        linkage.loads(text, source="my-scheme")


def test_unknown_scheme_lists_shipped_ones():
    shipped = sorted(p.stem for p in SCHEMES_DIR.glob("*.toml"))
    assert {"four_bar", "slider_crank", "slotted_link_two_dyad"} <= set(shipped)
    with pytest.raises(SchemeError, match="no_such_scheme") as info:
        linkage.load("no_such_scheme")
    for name in shipped:
        assert name in str(info.value)


def test_missing_scheme_file(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(SchemeError, match=re.escape(str(path))):
        linkage.load(path)


# ----------------------------------------------------------------------------------------------
# many problems at once
# ----------------------------------------------------------------------------------------------


def test_all_problems_reported_at_once(tmp_path):
    text = FOUR_BAR
    text = edit(text, 'input = "1"\n', 'input = "1"\ncolour = "red"\n')              # unknown top key
    text = edit(text, 'links = ["2", "3"]', 'links = ["2", "L7"]')                   # unknown link
    text = edit(text, "length = 0.25", "length = -0.25")                             # bad length
    text = edit(text, 'line = ["A", "B"]', 'line = ["A", "B"]\nmas = 1.0')           # unknown key
    text = edit(text, '[pairs.A]\nlinks = ["1", "2"]', '[pairs.A]\nlinks = ["1", "1"]')  # self pair
    text = edit(text, 'left_of = ["A", "C"]', 'left_of = ["A", "Z"]')                # unknown point
    text = edit(text, 'output = "3.theta"', 'output = "Z.x"')                        # bad output
    path = write(tmp_path, "many_problems.toml", text)
    with pytest.raises(SchemeError) as info:
        linkage.load(path)
    problems = info.value.problems
    expected = [
        ("colour",),
        ("pair 'B'", "'L7'"),
        ("link '3'", "-0.25"),
        ("links.2", "'mas'"),
        ("pair 'A'", "link '1'", "itself"),
        ("assembly of point 'B'", "'Z'"),
        ("output 'Z.x'",),
    ]
    for parts in expected:
        pattern = names(path, *parts)
        assert any(re.search(pattern, p) for p in problems), f"{parts} not in {problems}"
    assert len(problems) == len(expected), problems
    # one message per root cause: link 3's invalid line leaves its points C and B unplaced, and
    # the pairs pinned there are not reported again (issue 7)
    assert not any("pair 'C'" in p or "pair 'B': point" in p for p in problems), problems
    assert all(p.startswith(str(path)) for p in problems)
    assert str(info.value) == "\n".join(problems)


# ----------------------------------------------------------------------------------------------
# round trips
# ----------------------------------------------------------------------------------------------

SHIPPED = sorted(p.stem for p in SCHEMES_DIR.glob("*.toml"))


@pytest.mark.parametrize("name", SHIPPED)
def test_roundtrip_dumps_loads(name):
    mech = linkage.load(name)
    text = linkage.dumps(mech)
    again = linkage.loads(text)
    assert again == mech
    assert linkage.dumps(again) == text


@pytest.mark.parametrize("name", SHIPPED)
def test_roundtrip_save_load(tmp_path, name):
    mech = linkage.load(name)
    path = tmp_path / f"copy_of_{name}.toml"
    linkage.save(mech, path)
    assert linkage.load(path) == mech


def test_equality_is_not_vacuous():
    """The round-trip equality would notice a changed length."""
    mech = linkage.load("four_bar")
    changed = linkage.loads(linkage.dumps(mech).replace("B = [0.3, 0.0]", "B = [0.30000000000000004, 0.0]"))
    assert changed != mech


def test_shipped_schemes_load_after_plain_import():
    """``import linkage`` is enough to load every shipped scheme (fresh interpreter)."""
    code = ("import linkage\n"
            "for name in linkage.shipped_schemes():\n"
            "    linkage.load(name)\n")
    root = Path(__file__).resolve().parent.parent
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]
