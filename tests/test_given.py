"""Sheet-sufficient assignments: ``given.json`` holds every datum the answer key depends on, the
mechanism rebuilt from it alone gives the same key, and the sheet prints every datum of it.

Oracles: the original variant's own analyses (``template.mechanism``: dynamics summary,
kinematics and reactions tables, the answer key) against the same analyses of the mechanism
rebuilt from ``given.json`` after a JSON round trip, with no access to the template; the scheme's
leaves (every number and name of ``scheme.toml``) against the rows the sheet prints; the sheet's
figures (the drawing's scale against the standard scales and the room on paper).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

pytest.importorskip("matplotlib", reason="sheets need the plot extra (matplotlib)")

from linkage.course.given import (  # noqa: E402
    FURTHER,
    GRADING,
    data_sections,
    grading_from_given,
    grading_section,
    load_diagrams,
    scheme_from_given,
    scheme_leaves,
    sheet_rows,
)
from linkage.course.key import answer_key  # noqa: E402
from linkage.course.sheets import (  # noqa: E402
    PAPER_MARGIN,
    assignment_sheet_from_given,
    given_sheet_figures,
    sheet_figures,
)
from linkage.course.template import load_template, loads_template, shipped_templates  # noqa: E402
from linkage.course.typesetting import A4, BOTTOM  # noqa: E402
from linkage.course.variants import build_variant, select_variants, variant_name  # noqa: E402
from linkage.dynamics import run_dynamics  # noqa: E402
from linkage.report.results import forces_results, kinematics_results  # noqa: E402

#: standard scales paper / real, from the largest down (ISO 5455 and 1:2.5, 1:4, 1:25, 1:40 ...)
STANDARD = [100, 50, 20, 10, 5, 2] + [1 / (m * 10 ** k) for k in range(8) for m in (1, 2, 2.5, 4, 5)]

#: a template with every kind of load the [loads] section supports (a constant force, a diagram
#: with zones on the working and the idle stroke, a force along the line through two points, a
#: force fixed in a link with a signed diagram, a cycle table, a constant moment, a moment
#: diagram that drives) and every entry of [dynamics] (rotors, a flywheel, a start-up from rest
#: with a linear motor through a gear), with [template.grading]
EVERY_LOAD = """
name = "every_load"
input = "1"
output = { quantity = "B.x", start = "max" }

[links.0]
points = { O = [0.0, 0.0] }
guides.slide = { through = [0.0, "= offset"], angle_deg = 0, offset = 0.002 }

[links.1]
line = ["O", "A"]
length = "= crank"
mass = 5.0
com = [0.01, 0.0]
inertia = 0.02

[links.2]
line = ["A", "B"]
length = "= rod"
points.S2 = { from = "A", distance = "= 0.35 * rod" }
points.E = { from = "A", distance = "= 0.5 * rod", angle_deg = 20 }
mass = 12.0
com = "S2"
inertia = 0.3

[links.3]
points.B = [0.0, 0.0]
mass = 8.0
com = "B"

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

[loads]
gravity = [0.0, -9.81]

[[loads.forces]]
point = "E"
link = "2"
force = [30.0, -50.0]

[[loads.forces]]
point = "B"
link = "3"
diagram = { along = "x", working = "+", fractions = [0, 0.2, 0.2, 0.9, 1], values = [0, 0, "= peak", "= peak", 0], opposes = true, idle_fractions = [0, 0.5, 1], idle_values = [100, 100, 0] }

[[loads.forces]]
point = "E"
link = "2"
between = ["A", "E"]
magnitude = 40.0

[[loads.forces]]
point = "B"
link = "3"
along_link = "2"
angle_deg = 180
diagram = { quantity = "B.x", working = "-", fractions = [0, 0.5, 1], values = [0, -50, 20] }

[[loads.forces]]
point = "A"
link = "2"
along = "y"
cycle = [0, 10, 20, 30, 40, 50, 60, 50, 40, 30, 20, 10, 0]

[[loads.moments]]
link = "2"
moment = -3.0

[[loads.moments]]
link = "2"
diagram = { working = "+", fractions = [0, 1], values = [0, 5], opposes = false }

[dynamics]
mean_rpm = "= rpm"
delta = 0.04
positions = 12
inertia_0 = 1.5
rotors = [{ inertia = 0.001, ratio = 20.0 }]
flywheel = 0.5
initial_rpm = 0
cycles = 4

[dynamics.motor]
kind = "linear"
stall_moment = 60.0
no_load_rpm = 1500
ratio = 20.0
efficiency = 0.9

[template]
description = "Slider-crank with every kind of load and a motor"

[template.parameters]
crank = { values = [0.08, 0.1], unit = "m", label = "crank length OA" }
rod = { value = 0.35, unit = "m", label = "rod length AB" }
offset = { value = 0.01, unit = "m", label = "height of the guide's line" }
peak = { values = [1000, 2000], unit = "N", label = "peak resistance" }
rpm = { values = [-60, 90], unit = "rpm", label = "mean speed, signed" }

[template.grading]
points = ["B", "E"]
force_positions = [1, 4, 8]
tolerances = { "*.R" = 0.05 }
"""

CASES = [*shipped_templates(), "every_load"]


def _template(name):
    return loads_template(EVERY_LOAD, "every_load.toml") if name == "every_load" else load_template(name)


@pytest.fixture(scope="module")
def built():
    """name -> (template, variant, files of build_variant), made once per template."""
    made = {}

    def case(name):
        if name not in made:
            template = _template(name)
            variant = select_variants(template, count=1, seed=3).variants[0]
            made[name] = template, variant, build_variant(template, variant)
        return made[name]

    return case


def _given(files) -> dict:
    """given.json as a student's program reads it: the bytes, decoded, parsed."""
    return json.loads(files["given.json"].decode("utf-8"))


def _same(a, b, what):
    """Equal to 1e-12 relative to the larger magnitude (NaN where the other is NaN)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, what
    assert np.array_equal(np.isnan(a), np.isnan(b)), what
    ok = ~np.isnan(a)
    scale = max(float(np.max(np.abs(a[ok]), initial=0.0)), float(np.max(np.abs(b[ok]), initial=0.0)))
    assert np.all(np.abs(a[ok] - b[ok]) <= 1e-12 * scale), what


# -- the key from given.json alone ---------------------------------------------------------------


@pytest.mark.parametrize("name", CASES)
def test_the_mechanism_rebuilt_from_given_json_alone_has_the_variant_s_key(name, built):
    template, variant, files = built(name)
    original = template.mechanism(variant.free, name=variant_name(template, variant.label))
    given = _given(files)
    rebuilt = scheme_from_given(given)                         # no template from here on
    first, second = run_dynamics(original).summary(), run_dynamics(rebuilt).summary()
    assert first.keys() == second.keys()
    for field, value in first.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) and value is not None:
            _same(value, second[field], field)
        else:
            assert value == second[field], field
    for results in (kinematics_results, forces_results):        # the tables, the reactions among them
        a, b = results(original).columns, results(rebuilt).columns
        assert list(a) == list(b)
        for column in a:
            _same(a[column], b[column], f"{results.__name__} {column}")
    key = answer_key(rebuilt, grading_from_given(given))
    assert key.to_csv() == files["key.csv"].decode()            # every item, value and tolerance
    items = json.loads(files["key.json"])["items"]
    assert [(i["quantity"], i["position"], i["value"]) for i in items] == \
        [(i.quantity, i.position, i.value) for i in key.items]


@pytest.mark.parametrize("name", CASES)
def test_given_json_is_plain_deterministic_json(name, built):
    template, variant, files = built(name)
    text = files["given.json"].decode("utf-8")
    given = json.loads(text)
    assert text == json.dumps(given, ensure_ascii=False, indent=1, sort_keys=False, allow_nan=False) + "\n"
    assert "/tmp" not in text and "\\u" not in text                  # no path; real symbols, not escapes
    assert given["variant"] == variant.label and given["folder"] == variant.folder()
    assert given["template"] == template.name and given["tasks"] == list(template.tasks)
    assert given["description"] == template.description
    assert [p["name"] for p in given["parameters"]] == [p.name for p in template.parameters]
    assert {p["name"]: p["value"] for p in given["parameters"]} == template.values(variant.free)
    assert build_variant(template, variant)["given.json"] == files["given.json"]


# -- every datum on the sheet -------------------------------------------------------------------


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", text.replace("−", "-"))]


def _shows(row, value) -> bool:
    text = f"{row['quantity']} {row['value']}"
    if isinstance(value, bool):
        return ("yes" if value else "no") in row["value"]
    if isinstance(value, (int, float)):
        return any(math.isclose(x, value, rel_tol=1e-11, abs_tol=1e-300) for x in _numbers(text))
    return str(value) in text


@pytest.mark.parametrize("name", CASES)
def test_every_datum_of_the_scheme_is_in_the_sheet_s_rows(name, built):
    """Each leaf of given.json's scheme (every number and name the key can use) is shown by a row
    that names it in ``from``, and that row's text holds its value."""
    _, _, files = built(name)
    given = _given(files)
    rows = sheet_rows(given)
    leaves = scheme_leaves(given["scheme"])
    assert leaves
    for path, value in leaves.items():
        showing = [r for r in rows if any(path == s or path.startswith(s + ".") for s in r["from"])]
        assert showing, f"{name}: {path} = {value!r} is on no row of the sheet"
        assert any(_shows(r, value) for r in showing), (name, path, value, showing)
    # the rows are worded, not the fallback of raw scheme paths
    assert not [r for r in rows if r["section"] == FURTHER], name
    # the rows given.json holds are the ones its scheme gives (rendered from given.json alone)
    expected = [*data_sections(given["scheme"], given["position_1"]), grading_section(given["grading"],
                                                                                      given["position_1"])]
    assert given["data"] == json.loads(json.dumps(expected, ensure_ascii=False))
    assert given["diagrams"] == json.loads(json.dumps(load_diagrams(given["scheme"])))


def test_the_every_load_sheet_words_each_load_and_the_motor(built):
    given = _given(built("every_load")[2])
    rows = sheet_rows(given)
    text = " ".join(f"{r['quantity']} {r['value']} {r['unit']}" for r in rows)
    assert [s["title"] for s in given["data"]][-1] == GRADING
    for words in ["(30, −50) N", "A → E", "fixed in link 2", "see the load diagrams", "M₁, constant −3 N·m",
                  "no: it drives the motion", "linear", "60 N·m", "1500 rpm", "0.9", "rotor 1", "flywheel",
                  "B, E", "1, 4, 8", "tolerance of *.R 5 %", "0.04 (1/25)"]:
        assert words in text, words
    kinds = [(d["name"], d["kind"], len(d.get("strokes", []))) for d in given["diagrams"]]
    assert kinds == [("F2", "stroke", 2), ("F4", "stroke", 1), ("F5", "cycle", 0), ("M2", "stroke", 1)]
    peak = next(p["value"] for p in given["parameters"] if p["name"] == "peak")
    working, idle = given["diagrams"][0]["strokes"]
    assert [(z["from"], z["to"], z["start"], z["end"]) for z in working["zones"]] == \
        [(0, 0.2, 0, 0), (0.2, 0.9, peak, peak), (0.9, 1, peak, 0)]
    assert [(z["from"], z["to"], z["start"], z["end"]) for z in idle["zones"]] == [(0, 0.5, 100, 100), (0.5, 1, 100, 0)]


# -- the sheet ------------------------------------------------------------------------------------


def _texts(figures, gid):
    return [t.get_text() for fig in figures for t in fig.texts if t.get_gid() == gid]


def _squeeze(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize("name", ["press_slider_crank", "shaper_two_dyad", "every_load"])
def test_the_sheet_prints_every_row_of_given_json(name, built):
    _, _, files = built(name)
    given = _given(files)
    figures = given_sheet_figures(given)
    rows = [r for r in sheet_rows(given) if r["kind"] != "diagram"]
    assert _squeeze(" ".join(_texts(figures, "data-value"))) == _squeeze(" ".join(r["value"] for r in rows if r["value"]))
    assert _squeeze(" ".join(_texts(figures, "data-label"))) == _squeeze(" ".join(r["quantity"] for r in rows))
    assert _texts(figures, "data-symbol") == [r["symbol"] for r in rows]
    diagram_rows = [r for r in sheet_rows(given) if r["kind"] == "diagram"]
    assert _texts(figures, "diagram-value") == [r["value"] for r in diagram_rows]
    assert [ax.get_label() for fig in figures for ax in fig.axes if ax.get_label().startswith("diagram:")] == \
        [f"diagram:{d['name']}" for d in given["diagrams"]]
    assert _texts(figures, "title")[0] == given["title"]
    assert _texts(figures, "student-field") == ["Student:", "Group:", "Date:"]
    assert _texts(figures, "page-number") == [f"page {k} of {len(figures)}" for k in range(1, len(figures) + 1)]
    assert _squeeze(" ".join(_texts(figures, "task"))) == _squeeze(" ".join(given["tasks"]))
    # nothing outside the paper's margins, nothing below the footer's line
    for fig in figures:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for text in fig.texts:
            box = text.get_window_extent(renderer)
            assert box.x0 >= 10 / 25.4 * fig.dpi and box.x1 <= fig.bbox.x1 - 10 / 25.4 * fig.dpi, text.get_text()
            if text.get_gid() not in ("footer", "page-number"):
                assert box.y0 >= (BOTTOM - 0.05) * fig.dpi, text.get_text()
    assert files["sheet.pdf"] == assignment_sheet_from_given(given)          # the sheet is given.json's


def _scale(fig) -> float:
    text = " ".join(t.get_text() for t in fig.texts if t.get_gid() == "scale")
    paper, real = re.search(r"scale (\d+(?:\.\d+)?):(\d+(?:\.\d+)?)$", text).groups()
    return float(paper) / float(real)


@pytest.mark.parametrize("name", CASES)
def test_the_drawing_is_at_the_largest_standard_scale_that_fits_and_never_empty(name, built):
    """The data do not shrink the drawing: with every datum printed the next larger standard
    scale would not fit the width or the room page 1 has under the title block; and the drawing
    is drawn, all of it, in axes it fills."""
    _, _, files = built(name)
    given = _given(files)
    fig = given_sheet_figures(given)[0]
    scale = _scale(fig)
    assert any(math.isclose(scale, s, rel_tol=1e-12) for s in STANDARD)
    fig.canvas.draw()
    ax = next(a for a in fig.axes if a.get_label() == "drawing")
    pins = np.array([p.center for p in ax.patches if str(p.get_gid()).startswith("pair:")])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert len(pins) and np.all((pins[:, 0] > x0) & (pins[:, 0] < x1) & (pins[:, 1] > y0) & (pins[:, 1] < y1))
    drawn = ax.dataLim
    larger = min(s for s in STANDARD if s > scale * (1 + 1e-12))
    width, height = ax.get_position().width * A4[0], ax.get_position().height * A4[1]
    top = (ax.get_position().y1) * A4[1]
    room = top - BOTTOM - 0.5 - 0.26          # the x ticks and label, the 100 mm bar
    too_wide = drawn.width * larger / 0.0254 + 2 * PAPER_MARGIN > width
    too_tall = drawn.height * larger / 0.0254 + 2 * PAPER_MARGIN > room
    assert too_wide or too_tall, (scale, larger)
    # the drawing fills its axes: not a small drawing on empty axes
    assert drawn.width * scale / 0.0254 > 0.4 * width or drawn.height * scale / 0.0254 > 0.4 * height


def test_a_sheet_with_every_datum_keeps_the_drawing_of_the_shaper_at_its_scale():
    """The old layout shrank the shaper to 1:10 (and 1:20 with more rows) to keep the data on one
    page, and refused more than two pages: now the drawing keeps 1:4 and the rows go on."""
    template = load_template("shaper_two_dyad")
    mech = template.mechanism(select_variants(template, count=1, seed=3).variants[0].free)
    alone = _scale(sheet_figures(mech, title="T", data=[], tasks=[])[0])
    for rows in (10, 40, 120):
        data = [(f"quantity {k}", f"{k / 7:.6g}", "m") for k in range(rows)]
        figures = sheet_figures(mech, title="T", data=data, tasks=["Compute"] * 3)
        assert _scale(figures[0]) == alone
        assert _texts(figures, "data-value") == [v for _, v, _ in data]


@pytest.mark.parametrize("name", sorted(__import__("linkage").shipped_schemes()))
def test_every_shipped_scheme_is_worded_whole(name):
    """The rows word every entry of every shipped scheme (input laws, ranges, slide inputs,
    directed forces, motors ...), each naming it in ``from`` and showing its value."""
    import tomllib

    import linkage

    scheme = tomllib.loads(linkage.shipped_schemes()[name].read_text(encoding="utf-8"))
    given = {"data": data_sections(scheme, {}), "diagrams": load_diagrams(scheme)}
    rows = sheet_rows(given)
    assert not [r for r in rows if r["section"] == FURTHER], name
    for path, value in scheme_leaves(scheme).items():
        showing = [r for r in rows if any(path == s or path.startswith(s + ".") for s in r["from"])]
        assert any(_shows(r, value) for r in showing), (name, path, value)
