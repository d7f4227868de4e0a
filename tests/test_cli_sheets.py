"""``linkage sheets``: the command writes the sheets the scheme's data allow, in the formats asked,
notes the ones it leaves out naming the key to add, and refuses a bad option in one line."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import ezdxf
import pytest

import linkage
from linkage.course.project.frame import layout_problems
from linkage.course.project.model import Text
from linkage.course.project.sheets import drawn_position, project_sheets
from linkage.report.results import kinematics_results


def test_a_scheme_without_dynamics_gets_the_sheets_its_data_allow(linkage_run):
    run = linkage_run("sheets", "six_bar", "--out", "s", "--format", "pdf,dxf")
    assert run.status == 0, run.err
    written = sorted(p.name for p in (run.cwd / "s").iterdir())
    assert "six_bar_kinematics.pdf" in written and "six_bar_kinematics.dxf" in written
    assert not any("dynamics" in name for name in written)
    assert "the dynamics sheet is left out" in run.err and "[dynamics]" in run.err
    assert "Traceback" not in run.err
    # the DXF is a drawing in millimetres with the sheet's layers
    doc = ezdxf.readfile(run.cwd / "s" / "six_bar_kinematics.dxf")
    assert doc.header["$INSUNITS"] == 4
    layers = {layer.dxf.name for layer in doc.layers}
    assert {"frame", "positions", "plans", "text"} <= layers


def test_the_course_press_gets_its_three_sheets_numbered(linkage_run):
    run = linkage_run("sheets", "course_slider_crank", "--out", "s", "--format", "svg")
    assert run.status == 0, run.err
    names = sorted(p.name for p in (run.cwd / "s").iterdir())
    assert names == ["course_slider_crank_dynamics.svg", "course_slider_crank_kinematics.svg",
                     "course_slider_crank_kinetostatics.svg"]
    for name in names:
        head = (run.cwd / "s" / name).read_text(encoding="utf-8")[:2000]
        assert 'width="841' in head and 'height="594' in head and "mm" in head
    drawings, notes = project_sheets(linkage.load("course_slider_crank"))
    assert [name for name, _ in drawings] == ["kinematics", "kinetostatics", "dynamics"]
    scales = {**drawings[1][1].scales, **drawings[0][1].scales}
    assert notes == [f"the plans and polygons apart at the sheets' scales: linkage plans course_slider_crank "
                     f"--position 3 --mu-v {scales['μ_v'].value:g} --mu-a {scales['μ_a'].value:g} "
                     f"--mu-f {scales['μ_F'].value:g}"]
    for k, (_, drawing) in enumerate(drawings, start=1):
        texts = " ".join(item.text for item in drawing.items if isinstance(item, Text))
        assert f"{k} of 3" in texts.replace("Sheet", "sheet")


@pytest.mark.parametrize("argv, words", [
    (("--format", "pdf,png"), "--format"),
    (("--paper", "A0"), "invalid choice"),
    (("--position", "0"), "--position"),
])
def test_bad_options_are_refused_in_one_line(linkage_run, argv, words):
    run = linkage_run("sheets", "four_bar", "--out", "s", *argv)
    assert run.status == 2
    assert words in run.err and "Traceback" not in run.err


def test_the_default_position_is_where_the_output_moves_fastest():
    mech = linkage.load("course_slider_crank")
    results = kinematics_results(mech)
    speed = abs(results.columns[f"{mech.output.quantity}'"])
    i = drawn_position(mech)
    assert speed[i - 1] == max(speed) and i != 1


SHIPPED = sorted(p.stem for p in (Path(__file__).resolve().parents[1] / "schemes").glob("*.toml"))


@pytest.mark.skipif(not os.environ.get("LINKAGE_FUZZ"), reason="every shipped scheme's sheets: about 2 minutes; "
                                                               "set LINKAGE_FUZZ=1 (the sheet tests cover six schemes)")
@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_scheme_gets_its_sheets_without_a_layout_problem(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", linkage.PlausibilityWarning)
        drawings, notes = project_sheets(linkage.load(name))
    assert drawings and drawings[0][0] == "kinematics"
    for sheet, drawing in drawings:
        assert layout_problems(drawing) == [], (name, sheet)
    for note in notes:      # a sheet left out names what to add
        assert "left out" in note and ("add" in note or "driven by a slide" in note), note


@pytest.mark.parametrize("missing, formats, words", [
    ("matplotlib", "pdf", "needs the 'report' extra (matplotlib missing)"),
    ("ezdxf", "pdf,dxf", "needs ezdxf"),
])
def test_a_missing_extra_is_named_with_what_to_install(monkeypatch, capsys, tmp_path, missing, formats, words):
    import importlib.util

    from linkage.cli import main

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == missing else real(name, *a))
    assert main(["sheets", "four_bar", "--out", str(tmp_path / "s"), "--format", formats]) == 2
    err = capsys.readouterr().err
    assert words in err and 'pip install "linkage[report]"' in err and "Traceback" not in err
    assert not (tmp_path / "s").exists()


def test_the_title_block_names_the_student_group_and_variant(linkage_run):
    run = linkage_run("sheets", "four_bar", "--out", "s", "--format", "svg", "--student", "Ivanov I. I.",
                      "--group", "MT-21-3", "--variant", "12")
    assert run.status == 0, run.err
    text = (run.cwd / "s" / "four_bar_kinematics.svg").read_text(encoding="utf-8")
    for words in ("Ivanov I. I.", "MT-21-3", "12", "four_bar"):
        assert words in text
