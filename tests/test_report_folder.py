"""``linkage report SCHEME --out DIR``: the folder holds the expected files, the pictures are real
images, the page references only files that exist, and the tables equal the commands' own."""

from __future__ import annotations

import html.parser
import importlib.util
import xml.etree.ElementTree as ET

import pytest

pytest.importorskip("matplotlib", reason="the report needs the report extra (matplotlib)")
pytest.importorskip("jinja2", reason="the report needs the report extra (Jinja2)")
pytest.importorskip("tqdm", reason="the report needs the report extra (tqdm)")

from PIL import Image  # noqa: E402  (pillow comes with matplotlib)

from _cli_io import run  # noqa: E402

MACHINE_PICTURES = ("moments_and_work", "energy_inertia", "flywheel_energy", "speed_two_ways", "law_of_motion")
KINEMATIC_PICTURES = ("mechanism", "positions", "kinematic_diagrams", "balancing_moment", "hodographs")


class _References(html.parser.HTMLParser):
    """Every ``src`` and ``href`` of a page."""

    def __init__(self):
        super().__init__()
        self.targets: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.targets += [value for name, value in attrs if name in ("src", "href") and value]


def _report(linkage_run, scheme: str):
    """The report folder of ``linkage report SCHEME --out report`` (the README's command for the
    press: one run shared with tests/test_readme.py)."""
    done = linkage_run("report", scheme, "--out", "report")
    assert done.status == 0, done.err
    return done.cwd / "report"


@pytest.fixture(scope="module")
def press(linkage_run):
    return _report(linkage_run, "course_slider_crank")


@pytest.fixture(scope="module")
def four_bar(linkage_run):
    return _report(linkage_run, "four_bar")


def test_the_press_report_holds_every_table_picture_and_the_film(press):
    for name in ("index.html", "scheme.toml", "kinematics.csv", "forces.csv", "dynamics.csv", "dynamics.json"):
        assert (press / name).stat().st_size > 100, name
    for name in KINEMATIC_PICTURES + MACHINE_PICTURES:
        with Image.open(press / f"{name}.png") as image:
            width, height = image.size
        assert 700 <= width <= 1800 and 300 <= height <= 2600, (name, image.size)  # A4 text width at 150 dpi
        root = ET.parse(press / f"{name}.svg").getroot()
        assert root.tag.endswith("svg") and len(list(root.iter())) > 50, name
    with Image.open(press / "animation.gif") as film:
        assert film.n_frames == 72
        assert film.size[0] >= 300


def test_the_page_references_only_files_that_exist_and_shows_every_picture(press):
    page = (press / "index.html").read_text(encoding="utf-8")
    parser = _References()
    parser.feed(page)
    files = [t for t in parser.targets if not t.startswith("#")]
    assert files, "the page references no file"
    for target in files:
        assert "://" not in target and not target.startswith("/"), target  # the folder stands alone
        assert (press / target).is_file(), target
    for name in KINEMATIC_PICTURES + MACHINE_PICTURES:
        assert f"{name}.png" in files and f"{name}.svg" in files
    assert "animation.gif" in files
    assert "I(0,1) → II-RRP(2,3)" in page  # the structural formula
    assert "start-up" in page  # the note on the picture the scheme's data does not allow (no motor)


def test_the_report_tables_equal_the_commands_output(press, capsys):
    for command, name, fmt in (("analyze", "kinematics.csv", "csv"), ("forces", "forces.csv", "csv"),
                               ("dynamics", "dynamics.csv", "csv"), ("dynamics", "dynamics.json", "json")):
        code, out, _ = run(capsys, command, "course_slider_crank", "--format", fmt)
        assert code == 0
        assert (press / name).read_text(encoding="utf-8").strip() == out.strip(), name


def test_a_scheme_without_dynamics_gets_the_kinematic_pictures_and_a_note(four_bar):
    for name in KINEMATIC_PICTURES:
        assert (four_bar / f"{name}.png").is_file(), name
    for name in MACHINE_PICTURES:
        assert not (four_bar / f"{name}.png").exists(), name
    assert not (four_bar / "dynamics.csv").exists()
    assert "no [dynamics] section" in (four_bar / "index.html").read_text(encoding="utf-8")


def test_report_refuses_a_file_as_its_folder_and_says_what_to_install(tmp_path, capsys, monkeypatch):
    target = tmp_path / "taken"
    target.write_text("x")
    code, out, err = run(capsys, "report", "four_bar", "--out", str(target))
    assert code == 2 and "is a file, not a folder" in err and "Traceback" not in err

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "jinja2" else real(name, *a))
    code, out, err = run(capsys, "report", "four_bar", "--out", str(tmp_path / "r"))
    assert code == 2 and 'pip install "linkage[report]"' in err and "Jinja2" in err
