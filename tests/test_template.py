"""Course-assignment templates (linkage/template.py, docs/templates.md).

Oracles are computed here independently: grids with exact decimal arithmetic, expressions with
``math`` written out by hand, the strokes of the shipped mechanisms from their closed forms, and
the draws' set against the product of the grids.
"""

from __future__ import annotations

import itertools
import math
import tomllib
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.dynamics.pipeline import run_dynamics
from linkage.errors import InputError, SchemeError
from linkage.model.scheme import from_dict, loads, shipped_schemes, toml_text
from linkage.course.parameters import Parameter
from linkage.course.template import (
    Template,
    draws,
    given_variants,
    load_template,
    loads_template,
    shipped_templates,
)

#: a one-link scheme (a crank on the frame) whose length is the parameter ``r``
CRANK = '''
name = "bar"
input = "1"
[links.0]
points = { O = [0.0, 0.0] }
[links.1]
line = ["O", "A"]
length = "= r"
[pairs.O]
links = ["0", "1"]
'''


def template(parameters: str, body: str = CRANK, source: str = "t.toml") -> Template:
    return loads_template(body + "\n[template.parameters]\n" + parameters, source=source)


def choices(spec: str) -> tuple:
    return template("r = 0.1\n" + "g = " + spec).parameter("g").choices


def strings(value) -> list[str]:
    """Every string in nested tables and lists."""
    if isinstance(value, dict):
        return [s for v in value.values() for s in strings(v)]
    if isinstance(value, list):
        return [s for v in value for s in strings(v)]
    return [value] if isinstance(value, str) else []


# ----------------------------------------------------------------------------------------------
# grids
# ----------------------------------------------------------------------------------------------


def test_grid_is_inclusive_and_exact_in_decimals():
    got = choices("{ range = [0.06, 0.12], step = 0.005 }")
    exact = [float(Decimal("0.06") + k * Decimal("0.005")) for k in range(13)]
    assert got == tuple(exact)
    assert got[-1] == 0.12  # the end is on the grid, not 0.12000000000000001 or left out


@pytest.mark.parametrize("spec, expected", [
    ("{ range = [0.1, 0.3], step = 0.1 }", (0.1, 0.2, 0.3)),           # 0.1 + 2 * 0.1 = 0.30000000000000004
    ("{ range = [0.0, 0.3], step = 0.1 }", (0.0, 0.1, 0.2, 0.3)),      # (0.3 - 0) / 0.1 = 2.9999999999999996
    ("{ range = [0.0, 1.0], step = 0.3 }", (0.0, 0.3, 0.6, 0.9)),      # b off the grid: not reached
    ("{ range = [0.25, 0.25], step = 0.1 }", (0.25,)),                 # a single value
    ("{ range = [0.0615, 0.0715], step = 0.005 }", (0.0615, 0.0665, 0.0715)),  # a's decimals kept
    ("{ range = [2, 7], step = 2 }", (2, 4, 6)),
])
def test_grid_ends_and_rounding(spec, expected):
    got = choices(spec)
    assert got == expected
    assert all(type(g) is type(e) for g, e in zip(got, expected))


def test_parameter_kinds_in_declaration_order():
    t = template('r = { range = [1, 2], step = 1, unit = "m", label = "crank" }\nk = { values = ["a", "b"] }\n'
                 'd = { value = "= r * 2", round = 1 }\nc = 9.81\ne = "= c + r"\n')
    assert [p.name for p in t.parameters] == ["r", "k", "d", "c", "e"]
    assert [p.kind for p in t.parameters] == ["range", "values", "derived", "constant", "derived"]
    assert t.parameters[0] == Parameter("r", "range", "m", "crank", (1, 2))
    assert t.free == ("r", "k") and t.size == 4
    assert t.parameter("d").expression == "= r * 2" and t.parameter("d").round == 1


# ----------------------------------------------------------------------------------------------
# expressions
# ----------------------------------------------------------------------------------------------


def test_expressions_against_math():
    t = template('r = 0.1\na = { values = [3.0] }\nb = { values = [4.0] }\n'
                 'hyp = "= sqrt(a**2 + b**2)"\nang = "= degrees(atan2(b, a))"\nneg = "= -a ** 2"\n'
                 'spread = "= max(a, b) - min(a, b) + abs(-a)"\nthird = "= round(a / 7, 3)"\n'
                 'mix = "= (a + b) * 2 / 4 - pi"\ntrig = "= sin(radians(30)) + cos(0) + tan(pi / 4)"\n'
                 'inv = "= asin(0.5) + acos(0.5) + atan(1)"\nwhole = "= 2 * 6"\nquot = "= 12 / 4"\n'
                 'rounded = "= round(a * 1.9)"\n')
    v = t.values({"a": 3.0, "b": 4.0})
    assert v["hyp"] == 5.0
    assert v["ang"] == pytest.approx(math.degrees(math.atan(4 / 3)), abs=1e-12)
    assert v["neg"] == -9.0  # ** binds tighter than unary minus
    assert v["spread"] == 4.0
    assert v["third"] == 0.429
    assert v["mix"] == pytest.approx(3.5 - math.pi, abs=1e-15)
    assert v["trig"] == pytest.approx(0.5 + 1 + 1, abs=1e-12)
    assert v["inv"] == pytest.approx(math.pi / 2 + math.pi / 4, abs=1e-12)
    assert v["whole"] == 12 and type(v["whole"]) is int
    assert v["quot"] == 3.0 and type(v["quot"]) is float
    assert v["rounded"] == 6 and type(v["rounded"]) is int


@pytest.mark.parametrize("expression, says", [
    ("__import__('os').system('touch PWNED')", "__import__"),
    ("open('x')", "'open'"),
    ("eval('1')", "'eval'"),
    ("exec(1)", "'exec'"),
    ("a.real", "attribute"),
    ("math.pi", "attribute"),
    ("(1, 2)[0]", "Tuple"),
    ("lambda: 1", "lambda"),
    ("1 if a else 2", "if ... else"),
    ("a % 2", "'%'"),
    ("a // 2", "'//'"),
    ("a < 2", "comparison"),
    ("'text'", "constant"),
    ("sqrt(x=a)", "keyword"),
    ("sin(a, a)", "sin() with 2 arguments"),
])
def test_whitelist_refuses(expression, says, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SchemeError) as err:
        template(f'r = 0.1\na = 1.0\nx = "= {expression}"\n')
    message = str(err.value)
    assert "t.toml: [template.parameters] x:" in message and "not allowed" in message and says in message
    assert not (tmp_path / "PWNED").exists()


def test_unknown_names_suggest():
    with pytest.raises(SchemeError, match=r"\[template.parameters\] rod: unknown name 'crnk' in '= crnk / 2'; "
                                          r"did you mean 'crank'\?"):
        template('r = 0.1\ncrank = 0.1\nrod = "= crnk / 2"\n')
    with pytest.raises(SchemeError, match=r"a call of 'sqr' \(did you mean 'sqrt'\?\)"):
        template('r = "= sqr(2)"\n')
    with pytest.raises(SchemeError, match=r"t.toml: links.1.length: unknown name 'rr' in '= rr'; did you mean 'r'\?"):
        template("r = 0.1\n", CRANK.replace('"= r"', '"= rr"'))


def test_string_parameters_only_alone():
    with pytest.raises(SchemeError, match=r"'k' holds string values, which can only be used alone"):
        template('r = 0.1\nk = { values = ["a", "b"] }\nx = "= k * 2"\n')


def test_derived_in_any_order():
    t = template('c = "= b + 1"\nb = "= a * 2"\nr = "= c / 10"\na = { values = [1, 2] }\n')
    v = t.values({"a": 2})
    assert list(v) == ["c", "b", "r", "a"]  # declaration order
    assert v == {"c": 5, "b": 4, "r": 0.5, "a": 2}


def test_derived_cycle_names_the_parameters():
    with pytest.raises(SchemeError) as err:
        template('r = 0.1\nx = "= y + 1"\ny = "= z * 2"\nz = "= x / 3"\n')
    assert "t.toml: [template.parameters]: the derived parameters x, y, z depend on each other in a cycle" \
        in str(err.value)
    with pytest.raises(SchemeError, match=r"\[template.parameters\] x: the derived parameter uses itself"):
        template('r = 0.1\nx = "= x + 1"\n')


@pytest.mark.parametrize("expression, value, good, reason", [
    ("1 / (a - 1)", 1, 5, "division by zero"),
    ("sqrt(a - 2)", 1, 5, "math domain error"),
    ("(-a) ** 0.5", 1, -4, "math domain error"),
    ("10.0 ** (400 * a)", 1, 0, "error (math range error)"),
    ("a * 1e300 * 1e300", 1, 0, "gives inf"),
])
def test_non_finite_derived_names_parameter_and_values(expression, value, good, reason):
    t = template(f'a = {{ values = [{value}, {good}] }}\nr = "= {expression}"\n')
    with pytest.raises(InputError) as err:
        t.values({"a": value})
    message = str(err.value)
    assert "t.toml: [template.parameters] r:" in message and f"a = {value}" in message and reason in message
    assert math.isfinite(t.values({"a": good})["r"])


@pytest.mark.parametrize("line, says", [
    ("r = { range = [0.1, 0.3], step = -0.1 }", "[template.parameters] r: step must be > 0, got -0.1"),
    ("r = { range = [0.1, 0.3], step = 0 }", "[template.parameters] r: step must be > 0, got 0"),
    ("r = { range = [0.3, 0.1], step = 0.1 }", "[template.parameters] r: range [0.3, 0.1] gives an empty grid"),
    ("r = { range = [0.1, 0.3] }", "[template.parameters] r: a range needs a step"),
    ("r = { range = [0.1, nan], step = 0.1 }", "[template.parameters] r: range must be [a, b], two finite"),
    ("r = { values = [] }", "[template.parameters] r: values must be a non-empty list"),
    ("r = { values = [0.1, 0.1] }", "[template.parameters] r: values repeats 0.1"),
    ("r = { rnage = [0.1, 0.3], step = 0.1 }", "did you mean 'range'?"),
    ("r = { values = [0.1], value = 0.2 }", "give exactly one of 'range' (with 'step'), 'values' or 'value'"),
    ('r = { value = "= 0.1", round = 1.5 }', "[template.parameters] r: round must be a whole number"),
    ("r = 0.1\nsqrt = 2", "'sqrt' is reserved"),
    ("r = 0.1\nvariant = 2", "'variant' is reserved"),
    ("r = [0.1]", "[template.parameters] r: expected a finite number, a string"),
])
def test_parameter_errors_name_file_entry_and_value(line, says):
    with pytest.raises(SchemeError) as err:
        template(line + "\n")
    assert str(err.value).startswith("t.toml: ") and says in str(err.value)
    assert "links.1.length" not in str(err.value)  # no follow-on error from the body


def test_template_table_errors():
    with pytest.raises(SchemeError, match=r"not a template: a template has a \[template\] table"):
        loads_template(CRANK)
    with pytest.raises(SchemeError, match=r"\[template\]: unknown keys \['task'\].*did you mean 'tasks'\?"):
        loads_template(CRANK + '[template]\ntask = ["x"]\n[template.parameters]\nr = 0.1\n')
    with pytest.raises(SchemeError, match=r"\[template.require\]: expected a table"):
        loads_template(CRANK + '[template]\nrequire = 3\n[template.parameters]\nr = 0.1\n')


# ----------------------------------------------------------------------------------------------
# substitution into the scheme
# ----------------------------------------------------------------------------------------------

FOUR_BAR = '''
name = "fb"
input = "1"
output = { quantity = "= q", start = "= s" }
[links.0]
points = { O = [0.0, 0.0], C = ["= d", "= -e"] }
[links.1]
line = ["O", "A"]
length = "= r"
[links.2]
line = ["A", "B"]
length = "= 3 * r"
points.E = { from = "A", distance = "= 1.5 * r", angle_deg = "= 30 * k" }
[links.3]
line = ["C", "B"]
length = "= 2.5 * r"
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
[[loads.forces]]
point = "E"
link = "2"
force = ["= -f", 0.0]
[[loads.forces]]
point = "B"
link = "2"
force = [0.0, "= f / 2"]
[dynamics]
mean_rpm = "= rpm"
delta = 0.05
positions = "= n"
'''


def test_substitution_everywhere():
    t = template('r = { values = [0.1, 0.12] }\nd = "= 3 * r"\ne = { range = [0.0, 0.02], step = 0.01 }\n'
                 'k = 1\nf = { values = [100.0, 250.0] }\nrpm = 60\nn = { values = [12, 24] }\n'
                 'q = { values = ["3.theta", "E.y"] }\ns = { values = ["max", "min"] }\n', FOUR_BAR)
    free = {"r": 0.12, "e": 0.01, "f": 250.0, "n": 24, "q": "E.y", "s": "min"}
    data = t.scheme_data(free, name="fb_7")
    assert not [s for s in strings(data) if s.startswith("=")]
    assert data["name"] == "fb_7" and "r = 0.12" in data["description"]
    assert data["output"] == {"quantity": "E.y", "start": "min"}                       # strings stay strings
    assert data["links"]["0"]["points"]["C"] == [0.36, -0.01]                          # inside an inline table
    assert data["links"]["2"]["points"]["E"] == {"from": "A", "distance": pytest.approx(0.18, abs=1e-15),
                                                 "angle_deg": 30}
    assert data["links"]["3"]["length"] == pytest.approx(0.3, abs=1e-15)
    assert [f["force"] for f in data["loads"]["forces"]] == [[-250.0, 0.0], [0.0, 125.0]]  # arrays of tables
    assert data["dynamics"]["positions"] == 24 and type(data["dynamics"]["positions"]) is int
    assert t.body["links"]["1"]["length"] == "= r"                                     # the body is kept as written
    text = toml_text(data)
    assert tomllib.loads(text) == data
    mech = loads(text)
    assert mech.output.quantity == "E.y" and mech.output.start == "min"
    assert mech == t.mechanism(free, name="fb_7")


def test_values_accepts_off_grid_and_numpy_numbers_and_refuses_unknown_names():
    t = template('r = { range = [0.1, 0.3], step = 0.1 }\nk = { values = ["a", "b"] }\n')
    v = t.values({"r": np.float64(0.25), "k": "z"})
    assert v == {"r": 0.25, "k": "z"} and type(v["r"]) is float
    with pytest.raises(InputError, match=r"unknown free parameter 'rr'; did you mean 'r'\?.*no value for the free "
                                         r"parameters \['r'\]"):
        t.values({"rr": 0.1, "k": "a"})
    with pytest.raises(InputError, match=r"r: expected a finite number, got nan"):
        t.values({"r": float("nan"), "k": "a"})
    with pytest.raises(InputError, match=r"k: expected one of the strings \['a', 'b'\], got 3"):
        t.values({"r": 0.1, "k": 3})


def test_mechanism_errors_name_the_variant():
    t = template('r = { values = [0.1, -0.1] }\n')
    assert t.mechanism({"r": 0.1}).links["1"].points["A"] == (0.1, 0.0)
    with pytest.raises(SchemeError, match=r"t.toml \(r = -0.1\): .*length must be a number"):
        t.mechanism({"r": -0.1})


# ----------------------------------------------------------------------------------------------
# draws
# ----------------------------------------------------------------------------------------------


def small() -> Template:
    return template('r = { values = [0.1, 0.2] }\nk = { values = ["a", "b", "c"] }\nc = 1.0\n')


def test_draws_exhaust_a_small_grid_then_end():
    seq = list(itertools.islice(draws(small(), seed=3), 100))
    assert len(seq) == 6
    assert {tuple(d.items()) for d in seq} == {(("r", r), ("k", k)) for r in (0.1, 0.2) for k in "abc"}
    assert all(list(d) == ["r", "k"] for d in seq)


def test_draws_reproducible_and_seed_dependent():
    t = small()
    runs = {seed: [tuple(d.values()) for d in draws(t, seed)] for seed in range(8)}
    assert runs[5] == [tuple(d.values()) for d in draws(small(), 5)]
    assert len({tuple(run) for run in runs.values()}) > 1


def test_first_draw_takes_one_index_per_free_parameter():
    t = template('r = { range = [0.1, 0.9], step = 0.1 }\nk = { values = ["a", "b", "c"] }\nm = { range = [1, 50], '
                 'step = 1 }\n')
    indices = np.random.default_rng(11).integers(0, [9, 3, 50])
    first = next(draws(t, 11))
    assert first == {"r": round(0.1 * (indices[0] + 1), 1), "k": "abc"[indices[1]], "m": int(indices[2]) + 1}


def test_draws_of_a_larger_grid_are_distinct_and_complete():
    t = template('r = { range = [1, 12], step = 1 }\nk = { range = [0.5, 2.5], step = 0.5 }\n')
    seq = [(d["r"], d["k"]) for d in draws(t, 2024)]
    assert len(seq) == len(set(seq)) == t.size == 60
    assert set(seq) == set(itertools.product(range(1, 13), (0.5, 1.0, 1.5, 2.0, 2.5)))


def test_a_template_without_free_parameters_has_one_variant():
    t = template("r = 0.1\n")
    assert t.size == 1 and list(draws(t, 0)) == [{}]


# ----------------------------------------------------------------------------------------------
# given variants (CSV)
# ----------------------------------------------------------------------------------------------


def csv_template() -> Template:
    return template('r = { range = [0.1, 0.3], step = 0.1 }\nn = { values = [12, 24] }\nk = { values = ["a", "b"] }\n'
                    'x = "= 1 / (r - 0.5)"\n')


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "given.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_given_variants_with_labels_and_types(tmp_path):
    path = write(tmp_path, "variant,k,r,n\nA1,b,0.25,24\n\n# a comment\nA2, a ,0.1,12\n")
    got = given_variants(csv_template(), path)
    assert got == [("A1", {"r": 0.25, "n": 24, "k": "b"}), ("A2", {"r": 0.1, "n": 12, "k": "a"})]
    assert type(got[0][1]["n"]) is int and type(got[0][1]["r"]) is float


def test_given_variants_default_labels_semicolons_decimal_comma(tmp_path):
    path = write(tmp_path, "r;n;k\n0,15;12;a\n0,2;24;b\n")
    assert given_variants(csv_template(), path) == [("1", {"r": 0.15, "n": 12, "k": "a"}),
                                                    ("2", {"r": 0.2, "n": 24, "k": "b"})]


@pytest.mark.parametrize("text, says", [
    ("r,n,k\n0.1,12,a\nabc,24,b\n", "given.csv: line 3, column 'r': 'abc' is not a number"),
    ("r,n,k\nnan,12,a\n", "given.csv: line 2, column 'r': 'nan' is not a finite number"),
    ("r,n,k\n0.1,inf,a\n", "given.csv: line 2, column 'n': 'inf' is not a finite number"),
    ("r,n,k\n0.1,,a\n", "given.csv: line 2, column 'n': empty cell"),
    ("r,n,k\n0.1,12\n", "given.csv: line 2: 2 cells, the header has 3"),
    ("r,n,k\n0.5,12,a\n", "given.csv: line 2: t.toml: [template.parameters] x: '= 1 / (r - 0.5)' gives an error"),
    ("variant,r,n,k\nV,0.1,12,a\nV,0.2,12,a\n", "given.csv: line 3, column 'variant': the label 'V' repeats line 2"),
    ("rr,n,k\n0.1,12,a\n", "given.csv: header: column 'rr' is unknown; did you mean 'r'?"),
    ("r,n,k,x\n0.1,12,a,1\n", "column 'x' is a parameter computed by the template"),
    ("r,k\n0.1,a\n", "no column for the free parameters ['n']"),
    ("r,n,k\n", "given.csv: no variants: only a header"),
    ("", "given.csv: empty"),
])
def test_given_variants_errors(tmp_path, text, says):
    with pytest.raises(InputError) as err:
        given_variants(csv_template(), write(tmp_path, text))
    assert says in str(err.value)


# ----------------------------------------------------------------------------------------------
# the shipped templates
# ----------------------------------------------------------------------------------------------


def test_shipped_templates_are_found_and_not_listed_as_schemes():
    shipped = shipped_templates()
    assert {"press_slider_crank", "shaper_two_dyad", "press_crank_rocker"} <= set(shipped)
    assert not set(shipped) & set(shipped_schemes())
    with pytest.raises(SchemeError, match=r"unknown template 'press_slider'.*did you mean 'press_slider_crank'\?"):
        load_template("press_slider")
    with pytest.raises(SchemeError):  # a template is not a plain scheme
        linkage.load(shipped["press_slider_crank"])


@pytest.mark.parametrize("name", ["press_slider_crank", "shaper_two_dyad", "press_crank_rocker"])
def test_shipped_template_declares_what_the_generator_needs(name):
    t = load_template(name)
    assert t.name == name and t.description and len(t.tasks) >= 5
    assert {"full_rotation", "no_change_point", "non_singular", "min_transmission_angle_deg", "stroke"} <= set(t.require)
    assert all(t.parameter(n).label for n in t.free)
    assert t.size == math.prod(len(t.parameter(n).choices) for n in t.free) > 1000


def slide_stroke(r: float, l: float, e: float) -> float:
    """Stroke of the offset slider-crank: the slider at the two collinear positions of OA and AB."""
    return math.sqrt((l + r) ** 2 - e ** 2) - math.sqrt((l - r) ** 2 - e ** 2)


def shaper_stroke(r: float, d: float, h: float) -> float:
    """Stroke of the ram: the rocker at its extreme angles asin(r / d) either side of the vertical."""
    return 2 * h * r / math.sqrt(d ** 2 - r ** 2)


def measured_stroke(mech) -> float:
    x = linkage.analyze(mech, np.linspace(0, 2 * np.pi, 7201)).point("B")[:, 0]
    return float(x.max() - x.min())


def test_press_variants_build_run_and_match_closed_forms():
    t = load_template("press_slider_crank")
    for free in itertools.islice(draws(t, 1), 5):
        v = t.values(free)
        assert v["rod"] == round(free["crank"] / free["ratio"], 4)
        assert v["inertia_rod"] == round(v["mass_rod"] * v["rod"] ** 2 / 12, 3)
        mech = t.mechanism(free)
        assert mech.links["2"].mass == pytest.approx(v["q_rod"] * v["rod"], abs=0.051)
        stroke = slide_stroke(v["crank"], v["rod"], v["offset_ratio"] * v["crank"])
        assert measured_stroke(mech) == pytest.approx(stroke, rel=1e-5)
        report = run_dynamics(mech)
        assert report.summary()["driving_moment"] > 0


def test_shaper_variants_build_run_and_match_closed_forms():
    t = load_template("shaper_two_dyad")
    for free in itertools.islice(draws(t, 1), 5):
        mech = t.mechanism(free)
        stroke = shaper_stroke(free["crank"], free["pivots"], free["guide_height"])
        assert measured_stroke(mech) == pytest.approx(stroke, rel=1e-5)
        assert run_dynamics(mech).summary()["driving_moment"] > 0


def test_every_shaper_geometry_turns_fully_and_reaches_the_guide():
    """Closed form over the whole geometric grid: crank shorter than the pivot distance, the guide
    above the crank's circle, the rocker longer than the block B's farthest place on it."""
    t = load_template("shaper_two_dyad")
    grids = [t.parameter(n).choices for n in ("crank", "pivots", "guide_height", "rocker")]
    for r, d, h, length in itertools.product(*grids):
        assert r < d and h > d + r
        assert length >= h / math.sqrt(1 - (r / d) ** 2)
    base = next(draws(t, 1))
    for corner in itertools.product(*[(g[0], g[-1]) for g in grids]):
        free = {**base, **dict(zip(("crank", "pivots", "guide_height", "rocker"), corner))}
        assert measured_stroke(t.mechanism(free)) > 0  # assembles over the full turn (else AssemblyError)


def test_shaper_cuts_on_its_slow_stroke():
    """The diagram's working direction (-x) is the stroke that takes the larger crank angle."""
    t = load_template("shaper_two_dyad")
    free = next(draws(t, 1))
    mech = t.mechanism(free)
    assert free["rpm"] > 0  # counter-clockwise: phi increases with time
    x = linkage.analyze(mech, np.linspace(0, 2 * np.pi, 7201)).point("B")[:, 0]
    slow = np.mean(np.diff(x) < 0)
    theta = math.asin(free["crank"] / free["pivots"])
    assert slow == pytest.approx((math.pi + 2 * theta) / (2 * math.pi), abs=1e-3)
    assert t.body["loads"]["forces"][0]["diagram"]["working"] == "-"


def test_shipped_variant_written_as_a_plain_scheme(tmp_path):
    t = load_template("press_slider_crank")
    free = next(draws(t, 4))
    data = t.scheme_data(free, name="press_variant_1")
    assert not [s for s in strings(data) if s.startswith("=")]
    path = tmp_path / "press_variant_1.toml"
    path.write_text(toml_text(data), encoding="utf-8")
    mech = linkage.load(path)
    assert mech == from_dict(data) and mech.name == "press_variant_1"


def test_the_documented_example_template_works_for_every_variant():
    """The complete template of docs/templates.md: 30 variants, each a crank-rocker that turns fully."""
    text = (Path(__file__).resolve().parent.parent / "docs" / "templates.md").read_text(encoding="utf-8")
    block = text.split("## A complete small template", 1)[1].split("```toml\n", 1)[1].split("```", 1)[0]
    t = loads_template(block, source="docs/templates.md")
    variants = list(draws(t, 0))
    assert t.size == len(variants) == 30
    for free in variants:
        v = t.values(free)
        links = sorted([v["crank"], v["coupler"], v["rocker"], v["frame"]])
        assert links[0] == v["crank"] and links[0] + links[3] <= links[1] + links[2]  # Grashof, crank shortest
        motion = linkage.analyze(t.mechanism(free), np.linspace(0, 2 * np.pi, 73))
        assert np.all(motion.status == 0)
