"""``linkage variants``: feasible, distinct, reproducible variants; every answer key equals a direct
analysis of its variant's scheme; the rejection counts are right; a Dask cluster and worker
processes give the same files as a serial run."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import pytest

pytest.importorskip("matplotlib", reason="variants need the report extra (matplotlib)")
pytest.importorskip("jinja2", reason="variants need the report extra (Jinja2)")
pytest.importorskip("tqdm", reason="variants need the report extra (tqdm)")

import linkage  # noqa: E402
from _cli_io import run  # noqa: E402
from linkage.kinematics.feasibility import check, parse_requirements  # noqa: E402
from linkage.course.template import load_template, loads_template  # noqa: E402

FILES = ("scheme.toml", "sheet.pdf", "key.json", "kinematics.csv", "forces.csv", "dynamics.csv")


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
        assert _pages((folder / "sheet.pdf").read_bytes()) == 1
    assert _pages((serial / "index.pdf").read_bytes()) >= 1
    selection = json.loads((serial / "selection.json").read_text())
    assert selection["found"] == 3 and selection["seed"] == int(SEED) and selection["draws"] >= 3


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
        radii = sorted(float(r["r"]) for r in csv.DictReader(f))
    assert radii == sorted([0.07, 0.08, 0.09, 0.1, 0.11, 0.12] * 2)


def test_a_teachers_table_of_given_variants(tmp_path, capsys):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    table = tmp_path / "given.csv"
    table.write_text("variant,r,l\nA1,0.1,0.5\nA2,0.08,0.4\nbad,0.03,0.5\n")
    code, out, err = run(capsys, "variants", path, "--table", table, "--out", tmp_path / "o")
    assert code == 0, err
    assert (tmp_path / "o" / "variant_A1" / "key.json").is_file()
    assert (tmp_path / "o" / "variant_A2" / "key.json").is_file()
    assert not (tmp_path / "o" / "variant_bad").exists()
    assert "2 feasible variants" in err and "stroke 1" in err
    key = json.loads((tmp_path / "o" / "variant_A1" / "key.json").read_text())
    assert key["parameters"] == {"r": 0.1, "l": 0.5} and key["variant"] == "A1"


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
