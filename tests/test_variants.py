"""``linkage variants``: feasible, distinct, reproducible variants; every answer key equals a direct
analysis of its variant's scheme; the rejection counts are right; a Dask cluster and worker
processes give the same files as a serial run."""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

import pytest

pytest.importorskip("matplotlib", reason="variants need the report extra (matplotlib)")
pytest.importorskip("jinja2", reason="variants need the report extra (Jinja2)")
pytest.importorskip("tqdm", reason="variants need the report extra (tqdm)")

import linkage  # noqa: E402
from _cli_io import run  # noqa: E402
from linkage.kinematics.feasibility import check, parse_requirements  # noqa: E402
from linkage.course.template import load_template, loads_template  # noqa: E402
from linkage.course.sheets import assignment_sheet_from_given  # noqa: E402
from linkage.course.variants import select_variants  # noqa: E402

FILES = ("scheme.toml", "given.json", "sheet.pdf", "key.json", "key.csv", "answers.csv", "kinematics.csv",
         "forces.csv", "dynamics.csv")


def _pages(pdf: bytes) -> int:
    """Pages of a PDF: its page objects (``/Type /Page``, not ``/Pages``)."""
    return len(re.findall(rb"/Type\s*/Page(?![a-z])", pdf))


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


#: the seed of the README's `linkage variants press_slider_crank --count 3 --seed 1 --out assignments`
SEED = "1"


@pytest.fixture(scope="module")
def press(linkage_run, tmp_path_factory):
    """Three press variants, serial (the README's command: one run shared with
    tests/test_readme.py), and the same with two worker processes in another folder."""
    from linkage.cli import main

    done = linkage_run("variants", "press_slider_crank", "--count", "3", "--seed", SEED, "--out", "assignments")
    assert done.status == 0, done.err
    parallel = tmp_path_factory.mktemp("parallel") / "deeper" / "out"
    assert main(["variants", "press_slider_crank", "--count", "3", "--seed", SEED, "--out", str(parallel),
                 "--workers", "2"]) == 0
    return done.cwd / "assignments", parallel


def test_each_variant_folder_holds_its_files_and_the_index_lists_them(press):
    serial, _ = press
    with open(serial / "index.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["variant"] for r in rows] == ["1", "2", "3"]
    for row in rows:
        folder = serial / row["folder"]
        for name in FILES:
            assert (folder / name).stat().st_size > 100, (folder, name)
        # the sheet: every datum of given.json on as many pages as it needs, rendered from it alone
        sheet = (folder / "sheet.pdf").read_bytes()
        assert _pages(sheet) >= 2
        assert sheet == assignment_sheet_from_given(json.loads((folder / "given.json").read_text(encoding="utf-8")))
    assert _pages((serial / "index.pdf").read_bytes()) >= 1
    selection = json.loads((serial / "selection.json").read_text())
    assert selection["found"] == 3 and selection["seed"] == int(SEED) and selection["draws"] >= 3


def test_the_index_names_each_column_with_its_unit(press):
    """index.csv: ``name [unit]`` with the units of docs/conventions.md (the parameters' as the
    template declares them), a bare name for a pure number; index.pdf: the unit under each name,
    with real symbols."""
    serial, _ = press
    with open(serial / "index.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    header = list(rows[0])
    assert header == ["variant", "folder", "crank [m]", "ratio", "offset_ratio", "com_fraction", "q_rod [kg/m]",
                      "mass_slider [kg]", "peak_force [N]", "rpm [rpm]", "delta", "inertia_0 [kg m^2]", "stroke [m]",
                      "min_transmission_angle_deg [deg]", "driving_moment [N m]",
                      "required_constant_inertia [kg m^2]", "flywheel_inertia [kg m^2]", "dynamic_coefficient"]
    for row in rows:
        key = json.loads((serial / row["folder"] / "key.json").read_text())
        assert float(row["stroke [m]"]) == key["checks"]["stroke"]
        assert float(row["driving_moment [N m]"]) == key["driving_moment"]
        assert float(row["inertia_0 [kg m^2]"]) == key["parameters"]["inertia_0"]
    if shutil.which("pdftotext"):
        text = subprocess.run(["pdftotext", "-layout", str(serial / "index.pdf"), "-"], capture_output=True,
                              text=True, check=True).stdout
        lines = text.splitlines()
        names = next(k for k, line in enumerate(lines) if "crank" in line and "inertia_0" in line)
        units = next(line for line in lines[names + 1:] if "[m]" in line)
        assert units.split() == ["[m]", "—", "—", "—", "[kg/m]", "[kg]", "[N]", "[rpm]", "—", "[kg·m²]", "[m]",
                                 "[deg]", "[N·m]", "[kg·m²]", "[kg·m²]", "—"]


def test_the_same_seed_gives_byte_identical_files_whatever_the_folder_and_the_workers(press):
    serial, parallel = press
    assert _tree(serial) == _tree(parallel)
    for path, content in _tree(serial).items():
        if not path.endswith(".pdf"):
            assert str(serial).encode() not in content, path  # no absolute path inside


def test_every_answer_key_equals_a_direct_analysis_of_its_scheme(press, capsys):
    serial, _ = press
    for key_path in sorted(serial.glob("variant_*/key.json")):
        key = json.loads(key_path.read_text())
        code, out, err = run(capsys, "dynamics", key_path.parent / "scheme.toml", "--format", "json")
        assert code == 0, err
        direct = json.loads(out)
        for field, value in direct.items():
            assert key[field] == value, (key_path, field)
        assert {"variant", "template", "parameters", "checks"} <= set(key)
        code, out, _ = run(capsys, "analyze", key_path.parent / "scheme.toml", "--format", "csv")
        assert (key_path.parent / "kinematics.csv").read_text().strip() == out.strip()


def test_variants_are_distinct_and_feasible_by_an_independent_check(press):
    serial, _ = press
    template = load_template("press_slider_crank")
    requirements = parse_requirements(template.require, "press")
    seen = set()
    for key_path in sorted(serial.glob("variant_*/key.json")):
        key = json.loads(key_path.read_text())
        free = tuple(key["parameters"][n] for n in template.free)
        assert free not in seen
        seen.add(free)
        verdict = check(linkage.load(key_path.parent / "scheme.toml"), requirements)
        assert verdict.feasible, verdict.reason
        # the stroke of an offset slider-crank in closed form, from the key's parameters
        p = key["parameters"]
        r, rod, e = p["crank"], p["rod"], p["offset"]
        stroke = math.sqrt((rod + r) ** 2 - e ** 2) - math.sqrt((rod - r) ** 2 - e ** 2)
        assert key["checks"]["stroke"] == pytest.approx(stroke, rel=1e-8)
        low, high = template.require["stroke"]
        assert low <= stroke <= high


SMALL = """
name = "small_press"
input = "1"
output = { quantity = "B.x", start = "max" }
[links.0]
points = { O = [0.0, 0.0] }
guides.slide = { through = [0.0, 0.0], angle_deg = 0 }
[links.1]
line = ["O", "A"]
length = "= r"
[links.2]
line = ["A", "B"]
length = "= l"
mass = 1.0
com = "A"
[links.3]
points.B = [0.0, 0.0]
mass = 2.0
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
[dynamics]
mean_rpm = 60
delta = 0.05
positions = 12
inertia_0 = 1.0
[template.parameters]
r = { range = [0.05, 0.15], step = 0.01, unit = "m", label = "crank" }
l = { values = [0.4, 0.5], unit = "m", label = "rod" }
[template.require]
stroke = [0.13, 0.25]
"""


def test_rejections_are_counted_per_rule_as_the_closed_form_says(tmp_path, capsys):
    """Centred slider-crank: stroke = 2 r. Of the 22 combinations, r in [0.07, 0.12] (2 x 6 = 12)
    keep the stroke within [0.13, 0.25]; asking for more than 12 draws every combination."""
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    code, out, err = run(capsys, "variants", path, "--count", "15", "--seed", "3", "--out", tmp_path / "o")
    assert code == 2  # fewer than asked, said so
    assert "12 feasible variants of 15 asked from 22 draws" in err
    assert "rejected by rule: stroke 10" in err and "every combination" in err
    selection = json.loads((tmp_path / "o" / "selection.json").read_text())
    assert selection["rejected"]["stroke"] == 10 and selection["exhausted"] is True
    with open(tmp_path / "o" / "index.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    radii = sorted(float(r["r [m]"]) for r in rows)
    assert radii == sorted([0.07, 0.08, 0.09, 0.1, 0.11, 0.12] * 2)
    # folders named as documented: variant_K, K = 1 ... 12 without zero padding
    names = [f"variant_{k}" for k in range(1, 13)]
    assert [r["folder"] for r in rows] == names and [r["variant"] for r in rows] == [str(k) for k in range(1, 13)]
    assert sorted(p.name for p in (tmp_path / "o").glob("variant_*")) == sorted(names)


def test_a_teachers_table_of_given_variants(tmp_path, capsys):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    table = tmp_path / "given.csv"
    table.write_text("variant,r,l\nA1,0.1,0.5\nA2,0.08,0.4\nbad,0.03,0.5\n")
    code, out, err = run(capsys, "variants", path, "--table", table, "--out", tmp_path / "o", "--skip-infeasible")
    assert code == 0, err
    assert (tmp_path / "o" / "variant_A1" / "key.json").is_file()
    assert (tmp_path / "o" / "variant_A2" / "key.json").is_file()
    assert not (tmp_path / "o" / "variant_bad").exists()
    assert "2 feasible variants" in err and "stroke 1" in err
    # the note names the row left out (its line, label and values), the rule and the stroke measured
    left_out = [line for line in err.splitlines() if "left out:" in line]
    assert len(left_out) == 1, err
    assert "line 4" in left_out[0] and "'bad'" in left_out[0] and "r = 0.03, l = 0.5" in left_out[0]
    assert "stroke = [0.13, 0.25]" in left_out[0] and "0.06 m" in left_out[0]   # stroke 2 r = 0.06 m
    assert "widen" not in err
    key = json.loads((tmp_path / "o" / "variant_A1" / "key.json").read_text())
    assert key["parameters"] == {"r": 0.1, "l": 0.5} and key["variant"] == "A1"
    selection = json.loads((tmp_path / "o" / "selection.json").read_text())
    assert selection["table"] == "given.csv" and selection["rows"] == 3 and len(selection["left_out"]) == 1


def test_an_infeasible_given_row_is_an_error_naming_the_row_the_rule_and_the_value(tmp_path, capsys):
    """Without --skip-infeasible a row that breaks [template.require] refuses the table (exit 2,
    the input-error status), one line per such row, and nothing is written."""
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    table = tmp_path / "given.csv"
    # centred slider-crank: stroke = 2 r; r = 0.03 gives 0.06 m and r = 0.13 gives 0.26 m, both
    # outside [0.13, 0.25]; the rows without a variant column are labelled by their order
    table.write_text("r,l\n0.1,0.5\n0.03,0.5\n# a comment line\n0.08,0.4\n0.13,0.4\n")
    code, out, err = run(capsys, "variants", path, "--table", table, "--out", tmp_path / "o")
    assert code == 2 and "Traceback" not in err
    errors = [line for line in err.splitlines() if line.startswith("linkage: error:")]
    assert len(errors) == 3, err                 # the two rows, then what to do
    first, second, advice = errors
    assert "given.csv: line 3 (r = 0.03, l = 0.5)" in first and "stroke = [0.13, 0.25]" in first
    assert "is 0.06 m" in first
    assert "given.csv: line 6 (r = 0.13, l = 0.4)" in second and "is 0.26 m" in second
    assert "--skip-infeasible" in advice
    assert not (tmp_path / "o").exists()
    # the same in Python: an InputError; skip_infeasible=True leaves both rows out
    template = loads_template(SMALL)
    with pytest.raises(linkage.InputError, match=r"line 3 \(r = 0\.03, l = 0\.5\) breaks the rule stroke"):
        select_variants(template, 10, given=table)
    chosen = select_variants(template, 10, given=table, skip_infeasible=True)
    assert [v.label for v in chosen.variants] == ["1", "3"] and [v.draw for v in chosen.variants] == [2, 5]
    assert chosen.rejected == {"stroke": 2} and len(chosen.left_out) == 2
    # a transmission angle below the rule: named with the angle measured
    strict = loads_template(SMALL.replace("stroke = [0.13, 0.25]", "min_transmission_angle_deg = 80"))
    with pytest.raises(linkage.InputError) as info:
        select_variants(strict, 10, given=table)
    text = str(info.value)
    assert "line 2 (r = 0.1, l = 0.5) breaks the rule min_transmission_angle_deg = 80" in text
    # asin(r / l) = 11.54 deg from the perpendicular: 78.46 deg at worst
    assert f"{90 - math.degrees(math.asin(0.1 / 0.5)):.2f} deg" in text
    # --skip-infeasible without a table is refused
    code, _, err = run(capsys, "variants", path, "--seed", "1", "--count", "1", "--skip-infeasible",
                       "--out", tmp_path / "x")
    assert code == 2 and "--table" in err


def test_variants_refuse_bad_input_in_one_line(tmp_path, capsys):
    code, _, err = run(capsys, "variants", "press_slider_crank", "--count", "2", "--out", tmp_path / "o")
    assert code == 2 and "--seed" in err and "Traceback" not in err
    code, _, err = run(capsys, "variants", "no_such_template", "--seed", "1", "--out", tmp_path / "o")
    assert code == 2 and "no_such_template" in err and "Traceback" not in err
    code, _, err = run(capsys, "variants", "press_slider_crank", "--table", tmp_path / "none.csv",
                       "--out", tmp_path / "o")
    assert code == 2 and "none.csv" in err


def test_a_local_dask_cluster_gives_the_same_files_as_a_serial_run(tmp_path, capsys):
    distributed = pytest.importorskip("distributed", reason="the dask extra is not installed")
    template = loads_template(SMALL)
    assert template.size == 22
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    code, _, err = run(capsys, "variants", path, "--count", "3", "--seed", "11", "--out", tmp_path / "serial")
    assert code == 0, err
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        code, _, err = run(capsys, "variants", path, "--count", "3", "--seed", "11", "--out", tmp_path / "dask",
                           "--scheduler", cluster.scheduler_address)
    assert code == 0, err
    assert _tree(tmp_path / "serial") == _tree(tmp_path / "dask")
    code, _, err = run(capsys, "variants", path, "--count", "1", "--seed", "1", "--out", tmp_path / "x",
                       "--scheduler", "tcp://127.0.0.1:9")
    assert code == 2 and "cannot reach a Dask scheduler" in err


# ----------------------------------------------------------------------------------------------
# the six-link press: crank + RRR + RRP
# ----------------------------------------------------------------------------------------------


def _six_link_press(p: dict, phi: np.ndarray) -> dict[str, np.ndarray]:
    """The six-link press of schemes/templates/press_crank_rocker.toml in closed form, from its
    parameters: C at the origin, O at (a, b), A on the crank's circle, B where the circles about A
    (AB) and C (CB) meet on the left of A -> C, D on the line C -> B at CD, E on the vertical
    x = CD at DE below D. Returns the points and the two transmission angles (deg, acute)."""
    r, ab, cb, cd, de = p["crank"], p["coupler"], p["rocker"], p["arm"], p["rod"]
    ox, oy = p["frame_x"], p["frame_y"]
    ax, ay = ox + r * np.cos(phi), oy + r * np.sin(phi)
    ac = np.hypot(ax, ay)                                        # C is the origin
    along = (ab ** 2 - cb ** 2 + ac ** 2) / (2 * ac)            # from A towards C
    across = np.sqrt(ab ** 2 - along ** 2)
    ux, uy = -ax / ac, -ay / ac                                  # unit A -> C
    bx, by = ax + along * ux - across * uy, ay + along * uy + across * ux   # left of A -> C
    dx, dy = cd * bx / cb, cd * by / cb
    ex = np.full_like(phi, cd)
    ey = dy - np.sqrt(de ** 2 - (ex - dx) ** 2)
    # RRR: the angle between the coupler and the rocker at B, folded into [0, 90]
    cos_b = (ab ** 2 + cb ** 2 - ac ** 2) / (2 * ab * cb)
    gamma_b = np.degrees(np.arccos(np.clip(np.abs(cos_b), 0, 1)))
    # RRP: the rod DE against the guide's normal (horizontal)
    gamma_e = np.degrees(np.arctan2(np.abs(ey - dy), np.abs(ex - dx)))
    return {"B": np.stack([bx, by], 1), "E": np.stack([ex, ey], 1), "gamma_B": gamma_b, "gamma_E": gamma_e}


def test_the_six_link_press_template_turns_fully_over_its_whole_grid():
    """Grashof over every combination of the geometric grids: the crank is the shortest link and
    shortest + longest < the other two (by at least 0.02 m), so the crank turns fully."""
    t = load_template("press_crank_rocker")
    grids = [t.parameter(n).choices for n in ("crank", "coupler", "rocker", "frame_x", "frame_y")]
    for r, ab, cb, a, b in itertools.product(*grids):
        links = sorted([r, ab, cb, math.hypot(a, b)])
        assert links[0] == r and links[0] + links[3] <= links[1] + links[2] - 0.02 + 1e-12


def test_the_six_link_press_variants_are_feasible_by_an_independent_check():
    """Five variants of the six-link press (the docs' `--count 5 --seed 1`) chosen in a few
    seconds; each is a Grashof crank-rocker, and its stroke and smallest transmission angle,
    computed here in closed form, meet [template.require] and equal the figures the selection
    measured; the library's analysis of the variant gives the same points."""
    t = load_template("press_crank_rocker")
    chosen = select_variants(t, 5, seed=1)
    assert len(chosen.variants) == 5 and chosen.draws <= 20
    low, high = t.require["stroke"]
    phi = np.linspace(0.0, 2 * np.pi, 20001)
    for v in chosen.variants:
        p = t.values(v.free)
        links = sorted([p["crank"], p["coupler"], p["rocker"], math.hypot(p["frame_x"], p["frame_y"])])
        assert links[0] == p["crank"] and links[0] + links[3] < links[1] + links[2]    # Grashof crank-rocker
        ours = _six_link_press(p, phi)
        stroke = float(np.ptp(ours["E"][:, 1]))
        gamma = float(min(ours["gamma_B"].min(), ours["gamma_E"].min()))
        assert low <= stroke <= high and gamma >= t.require["min_transmission_angle_deg"]
        assert v.figures["stroke"] == pytest.approx(stroke, rel=1e-6)
        assert v.figures["min_transmission_angle_deg"] == pytest.approx(gamma, abs=1e-3)
        motion = linkage.analyze(t.mechanism(v.free), phi[::1000])
        assert np.allclose(motion.point("B"), ours["B"][::1000], atol=1e-10)
        assert np.allclose(motion.point("E"), ours["E"][::1000], atol=1e-10)
