"""``linkage grade``: answers checked against the keys of a class folder (linkage/course/grading.py).

The keys here are written by hand (key.csv, key.json), so the expected grades are known without
the library: a perfect answer set scores 100 %, a perturbed one fails exactly the perturbed items,
each usual mistake gets its hint, each bad input a message naming the file, the line and the value.
"""

from __future__ import annotations

import csv
import io
import json
import math
import random
from pathlib import Path

import pytest
from _cli_io import run

from linkage.course.grading import (
    ANSWER_COLUMNS,
    GRADE_COLUMNS,
    ITEM_COLUMNS,
    NO_ANSWER,
    answers_template,
    grade,
    hint_for,
    read_class,
    write_grades,
)
from linkage.errors import InputError, LinkageError

#: variant_1's key: (quantity, position, value, unit, tolerance)
KEY_1 = [
    ("B.x", 1, 0.30, "m", 0.02), ("B.x", 2, 0.25, "m", 0.02), ("B.x", 3, 0.12, "m", 0.02), ("B.x", 4, 0.20, "m", 0.02),
    ("B.v", 1, 0.0, "m/s", 0.02), ("B.v", 2, -1.5, "m/s", 0.02), ("B.v", 3, -0.8, "m/s", 0.02),
    ("B.v", 4, 1.9, "m/s", 0.02),
    ("2.omega", 1, 5.2, "rad/s", 0.02), ("2.omega", 2, -3.1, "rad/s", 0.02),
    ("2.theta_deg", 1, -30.0, "deg", 0.02), ("2.theta_deg", 2, 150.0, "deg", 0.02),
    ("12.R", 1, 4200.0, "N", 0.02), ("12.R", 2, 3100.0, "N", 0.02),
    ("driving_moment", None, 125.5, "N m", 0.01), ("flywheel_inertia", None, 0.85, "kg m^2", 0.02),
]
#: variant_2's key: other numbers, and the same items
KEY_2 = [(q, p, round(v * 1.1, 6), u, t) for q, p, v, u, t in KEY_1]


def _key_csv(rows) -> str:
    lines = ["quantity,position,value,unit,tolerance"]
    lines += [f"{q},{'' if p is None else p},{v!r},{u},{t!r}" for q, p, v, u, t in rows]
    return "\n".join(lines) + "\n"


def _write_class(folder: Path, keys=(KEY_1, KEY_2), json_items=None) -> Path:
    for k, rows in enumerate(keys, 1):
        variant = folder / f"variant_{k}"
        variant.mkdir(parents=True)
        (variant / "key.csv").write_text(_key_csv(rows), encoding="utf-8")
        (variant / "answers.csv").write_text(answers_template(_key_csv(rows), variant.name), encoding="utf-8")
        if json_items is not None:
            data = {"variant": str(k), "template": "press_slider_crank", "digits": 4,
                    "items": json_items(rows)}
            (variant / "key.json").write_text(json.dumps(data), encoding="utf-8")
    return folder


def _answers(rows) -> str:
    """answers.csv text from (student, variant, quantity, position, value) rows."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(ANSWER_COLUMNS)
    writer.writerows(["" if c is None else c for c in row] for row in rows)
    return buffer.getvalue()


def _perfect(student: str, variant: str, key) -> list[tuple]:
    return [(student, variant, q, p, repr(v)) for q, p, v, _, _ in key]


@pytest.fixture()
def klass(tmp_path):
    return _write_class(tmp_path / "class")


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


# ----------------------------------------------------------------------------------------------
# scores
# ----------------------------------------------------------------------------------------------


def test_a_perfect_answer_set_scores_100(klass, tmp_path):
    answers = tmp_path / "answers"
    _write(answers / "ann.csv", _answers(_perfect("Ann", "variant_1", KEY_1)))
    _write(answers / "bob.csv", _answers(_perfect("Bob", "variant_2", KEY_2)))
    grades = grade(klass, answers)
    assert [(s.student, s.variant, s.items, s.passed, s.score) for s in grades.students] == [
        ("Ann", "variant_1", len(KEY_1), len(KEY_1), 100.0), ("Bob", "variant_2", len(KEY_2), len(KEY_2), 100.0)]
    assert all(i.passed and i.hint == "" and i.relative_error == 0 for i in grades.items)


def test_a_perturbed_set_fails_exactly_the_perturbed_items(klass, tmp_path):
    rng = random.Random(3)
    perturbed = set(rng.sample(range(len(KEY_1)), 6))
    rows = []
    for k, (q, p, v, _, t) in enumerate(KEY_1):
        scale = max(abs(v), max(abs(r[2]) for r in KEY_1 if r[0] == q))
        # inside the tolerance (0.6 of it) or well outside it (3 times it), never a usual mistake
        rows.append(("Ann", "variant_1", q, p, repr(v + (3.0 if k in perturbed else 0.6) * t * scale)))
    grades = grade(klass, _write(tmp_path / "answers.csv", _answers(rows)))
    failed = {k for k, item in enumerate(grades.items) if not item.passed}
    assert failed == perturbed
    assert grades.students[0].passed == len(KEY_1) - len(perturbed)
    assert grades.students[0].score == pytest.approx(100 * (len(KEY_1) - len(perturbed)) / len(KEY_1))
    for k, item in enumerate(grades.items):
        assert item.relative_error == pytest.approx(3.0 * item.tolerance if k in perturbed else 0.6 * item.tolerance)


def test_the_pass_rule_uses_the_floor_near_zero(klass, tmp_path):
    # B.v at position 1 is 0: with no key.json the floor is the largest |B.v| over the positions (1.9)
    ok, bad = 0.02 * 1.9 * 0.9, 0.02 * 1.9 * 1.1
    grades = grade(klass, _write(tmp_path / "a.csv", _answers([("Ann", "variant_1", "B.v", 1, repr(ok)),
                                                                 ("Bob", "variant_1", "B.v", 1, repr(bad))])))
    by = {(i.student, i.quantity, i.position): i for i in grades.items}
    assert by[("Ann", "B.v", "1")].passed and not by[("Bob", "B.v", "1")].passed


def test_the_floor_and_the_digits_of_key_json(tmp_path):
    def items(rows):
        return [{"quantity": q, "position": p, "value": v, "unit": u, "tolerance": t, "digits": 3,
                 "floor": 10.0 if q == "B.v" else abs(v)} for q, p, v, u, t in rows]
    klass = _write_class(tmp_path / "class", json_items=items)
    keys = read_class(klass)
    assert keys["variant_1"].item("B.v", "1").floor == 10.0
    assert keys["variant_1"].item("B.x", "2").floor == 0.25   # not the largest B.x (0.30): key.json says
    assert keys["variant_1"].template == "press_slider_crank"
    grades = grade(klass, _write(tmp_path / "a.csv", _answers([("Ann", "variant_1", "B.v", 1, "0.19")])))
    assert grades.items[4].passed           # |0.19| <= 0.02 * 10


def test_angles_in_degrees_are_compared_modulo_360(klass, tmp_path):
    rows = [("Ann", "variant_1", "2.theta_deg", 1, "330"), ("Ann", "variant_1", "2.theta_deg", 2, "-210.5")]
    grades = grade(klass, _write(tmp_path / "a.csv", _answers(rows)))
    by = {(i.quantity, i.position): i for i in grades.items}
    assert by[("2.theta_deg", "1")].passed and by[("2.theta_deg", "2")].passed


def test_a_missing_answer_fails_with_the_hint_no_answer(klass, tmp_path):
    rows = _perfect("Ann", "variant_1", KEY_1)[:-3]
    grades = grade(klass, _write(tmp_path / "a.csv", _answers(rows)))
    missing = [i for i in grades.items if i.given is None]
    assert [(i.quantity, i.passed, i.hint) for i in missing] == [
        (q, False, NO_ANSWER) for q, *_ in KEY_1[-3:]]
    assert grades.students[0].passed == len(KEY_1) - 3


def test_the_filled_template_is_graded_and_empty_rows_are_not_answers(klass, tmp_path):
    lines = (klass / "variant_1" / "answers.csv").read_text(encoding="utf-8").splitlines()
    assert lines[0] == ",".join(ANSWER_COLUMNS) and len(lines) == len(KEY_1) + 1
    filled = [lines[0]]
    for line, (_, _, v, _, _) in zip(lines[1:], KEY_1):
        student, variant, quantity, position, value = line.split(",")
        assert (student, variant, value) == ("", "variant_1", "")
        filled.append(",".join(["Ann", variant, quantity, position, repr(v) if quantity != "B.x" else ""]))
    grades = grade(klass, _write(tmp_path / "ann.csv", "\n".join(filled) + "\n"))
    assert [i.hint for i in grades.items if not i.passed] == [NO_ANSWER] * 4


def test_a_name_written_once_or_the_files_name(klass, tmp_path):
    rows = _perfect("", "variant_1", KEY_1)
    _write(tmp_path / "answers" / "petrov.csv", _answers(rows))
    _write(tmp_path / "answers" / "x.csv", _answers([("Ann Lee",) + rows[0][1:]] + rows[1:]))
    grades = grade(klass, tmp_path / "answers")
    assert [(s.student, s.score) for s in grades.students] == [("Ann Lee", 100.0), ("petrov", 100.0)]


def test_a_spreadsheet_file_with_semicolons_and_decimal_commas(klass, tmp_path):
    text = "student;variant;quantity;position;value\nAnn;variant_1;B.x;1;0,3\nAnn;variant_1;B.v;2;\u22121,5\n"
    grades = grade(klass, _write(tmp_path / "a.csv", text))
    assert [i.given for i in grades.items if i.given is not None] == [0.3, -1.5]
    assert all(i.passed for i in grades.items if i.given is not None)


# ----------------------------------------------------------------------------------------------
# hints
# ----------------------------------------------------------------------------------------------

MISTAKES = [   # (quantity, position, given, hint)
    ("B.v", 2, 1.5, "wrong sign"),
    ("B.x", 2, 250.0, "mm instead of m (given = 1000 x the key)"),
    ("B.v", 3, -800.0, "mm/s instead of m/s (given = 1000 x the key)"),
    ("12.R", 1, 4.2, "kN instead of N (given = 1/1000 x the key)"),
    ("driving_moment", None, 0.1255, "kN m instead of N m (given = 1/1000 x the key)"),
    ("2.omega", 1, 5.2 * 30 / math.pi, "rpm instead of rad/s (given = 30/pi x the key)"),
    ("2.omega", 2, 3.1 * 30 / math.pi, "wrong sign and rpm instead of rad/s (given = -30/pi x the key)"),
    ("2.omega", 1, 5.2 * 180 / math.pi, "degrees instead of radians (given = 180/pi x the key)"),
    ("2.theta_deg", 2, math.radians(150.0), "radians instead of degrees (given = pi/180 x the key)"),
    ("2.theta_deg", 1, 150.0, "the opposite direction (180 deg off)"),
    ("B.x", 3, 0.2, "the value at position 4 (wrong position?)"),
    ("B.x", 3, 0.05, ""),
]


@pytest.mark.parametrize("quantity, position, given, hint", MISTAKES)
def test_each_usual_mistake_gets_its_hint(klass, tmp_path, quantity, position, given, hint):
    grades = grade(klass, _write(tmp_path / "a.csv", _answers([("Ann", "variant_1", quantity, position, repr(given))])))
    item = next(i for i in grades.items if i.given is not None)
    assert not item.passed
    assert item.hint == hint


def test_the_other_assembly_mode_when_the_key_has_it(tmp_path):
    def items(rows):
        return [{"quantity": q, "position": p, "value": v, "unit": u, "tolerance": t, "digits": 4,
                 **({"other_mode": 0.41} if (q, p) == ("B.x", 1) else {})} for q, p, v, u, t in rows]
    klass = _write_class(tmp_path / "class", json_items=items)
    grades = grade(klass, _write(tmp_path / "a.csv", _answers([("Ann", "variant_1", "B.x", 1, "0.412")])))
    assert grades.items[0].hint == "the other assembly mode"


def test_a_hint_needs_the_mistake_told_apart_from_the_right_value():
    # near zero (|expected| << floor) a factor 1000 cannot be told from a wrong answer
    assert hint_for(0.9, 0.001, 0.02, 1.0, "m") == ""
    assert hint_for(10.0, 0.01, 0.02, 0.3, "m") == "mm instead of m (given = 1000 x the key)"
    assert hint_for(0.01, 0.01, 0.02, 0.3, "m") == ""          # passes: no hint
    assert hint_for(-0.001, 0.001, 0.02, 1.0, "m") == ""       # passes through the floor
    # an analog per radian of crank rotation
    assert hint_for(50.0, 0.05, 0.02, 0.06, "m/rad") == "mm/rad instead of m/rad (given = 1000 x the key)"
    assert hint_for(0.05 * math.pi / 180, 0.05, 0.02, 0.06, "m/rad") == (
        "per degree instead of per radian (given = pi/180 x the key)")


# ----------------------------------------------------------------------------------------------
# errors
# ----------------------------------------------------------------------------------------------

BAD = [   # (file text, words the message must hold)
    (_answers([("Ann", "variant_9", "B.x", 1, "0.3")]), ["line 2", "unknown variant 'variant_9'"]),
    (_answers([("Ann", "variant_1", "C.x", 1, "0.3")]), ["line 2", "unknown quantity 'C.x'", "variant_1"]),
    (_answers([("Ann", "variant_1", "B.x", 1, "0.3"), ("Ann", "variant_1", "B.x", 7, "0.3")]),
     ["line 3", "unknown position '7' of B.x", "1 .. 4"]),
    (_answers([("Ann", "variant_1", "driving_moment", 1, "0.3")]), ["line 2", "driving_moment", "position empty"]),
    (_answers([("Ann", "variant_1", "B.x", 1, "0.3m")]), ["line 2", "value '0.3m' of B.x is not a number"]),
    (_answers([("Ann", "variant_1", "B.x", 1, "nan")]), ["line 2", "'nan'", "not a number"]),
    ("student,variant,quantity,value\nAnn,variant_1,B.x,0.3\n", ["line 1", "missing column position"]),
    ("student,variant,quantity,position,value,unit\n", ["line 1", "unknown column 'unit'"]),
    ("student,variant,quantity,position,value\nAnn,variant_1,B.x,1,0,3\n", ["line 2", "6 cells", "decimal comma"]),
    ("", ["empty file"]),
    ("\n  \n", ["empty file"]),
    (_answers([("Ann", "variant_1", "B.x", 1, "0.3"), ("Ann", "variant_1", "B.x", "1.0", "0.3")]),
     ["line 3", "twice", "line 2"]),
]


@pytest.mark.parametrize("text, words", BAD)
def test_bad_answers_are_named_with_file_line_and_value(klass, tmp_path, text, words):
    path = _write(tmp_path / "answers" / "ann.csv", text)
    with pytest.raises(InputError) as caught:
        grade(klass, path)
    message = str(caught.value)
    assert str(path) in message
    for word in words:
        assert word in message


@pytest.mark.parametrize("text, words", BAD[:5] + BAD[6:10])
def test_the_cli_says_each_error_in_one_line_and_exits_2(klass, tmp_path, capsys, text, words):
    path = _write(tmp_path / "answers" / "ann.csv", text)
    code, out, err = run(capsys, "grade", klass, path.parent, "--out", tmp_path / "grades")
    assert code == 2 and out == ""
    assert "Traceback" not in err and err.startswith("linkage: error: ")
    assert str(path) in err and all(word in err for word in words)
    assert not (tmp_path / "grades").exists()


def test_every_problem_of_a_class_is_said_at_once(klass, tmp_path):
    _write(tmp_path / "answers" / "a.csv", BAD[0][0])
    _write(tmp_path / "answers" / "b.csv", BAD[4][0])
    with pytest.raises(InputError) as caught:
        grade(klass, tmp_path / "answers")
    lines = str(caught.value).splitlines()
    assert len(lines) == 2 and "a.csv" in lines[0] and "b.csv" in lines[1]


def test_folders_without_keys_or_answers(klass, tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="no variant folder with a key.csv"):
        grade(tmp_path / "empty", tmp_path)
    with pytest.raises(InputError, match="no .csv file"):
        grade(klass, tmp_path / "empty")
    with pytest.raises(InputError, match="no such file or folder"):
        grade(klass, tmp_path / "nowhere.csv")
    code, _, err = run(capsys, "grade", tmp_path / "nowhere", tmp_path / "empty")
    assert code == 2 and "nowhere: no such folder" in err
    assert issubclass(InputError, LinkageError)


# ----------------------------------------------------------------------------------------------
# the command and its files
# ----------------------------------------------------------------------------------------------


def test_the_cli_prints_the_scores_and_writes_the_three_kinds_of_files(klass, tmp_path, capsys):
    answers = tmp_path / "answers"
    _write(answers / "ann.csv", _answers(_perfect("Ann", "variant_1", KEY_1)))
    wrong = _perfect("O'Neil <b>", "variant_2", KEY_2)
    wrong[0] = wrong[0][:4] + ("330",)      # B.x at 1 in mm: 1000 x 0.33
    _write(answers / "oneil.csv", _answers(wrong))
    _write(answers / "blank.csv", answers_template(_key_csv(KEY_1), "variant_1"))
    code, out, err = run(capsys, "grade", klass, answers, "--out", tmp_path / "grades")
    assert code == 0
    assert "blank.csv: no answers in it" in err
    table = [line.split() for line in out.splitlines()]
    assert table[0] == ["student", "variant", "items", "passed", "score"]
    assert table[1] == ["Ann", "variant_1", "16", "16", "100", "%"]
    assert table[2][-5:] == ["variant_2", "16", "15", "93.8", "%"]
    folder = tmp_path / "grades"
    assert sorted(p.name for p in folder.iterdir()) == ["grades.csv", "items.csv", "student_Ann.html",
                                                        "student_O_Neil_b.html"]
    grades = list(csv.reader(io.StringIO((folder / "grades.csv").read_text(encoding="utf-8"))))
    assert grades == [list(GRADE_COLUMNS), ["Ann", "variant_1", "16", "16", "100"],
                      ["O'Neil <b>", "variant_2", "16", "15", "93.8"]]
    items = list(csv.DictReader(io.StringIO((folder / "items.csv").read_text(encoding="utf-8"))))
    assert list(items[0]) == list(ITEM_COLUMNS) and len(items) == 32
    bad = [row for row in items if row["passed"] == "0"]
    assert len(bad) == 1 and bad[0]["hint"].startswith("mm instead of m")
    assert (float(bad[0]["expected"]), float(bad[0]["given"]), float(bad[0]["relative_error"])) == (
        0.33, 330.0, pytest.approx(999.0))
    page = (folder / "student_O_Neil_b.html").read_text(encoding="utf-8")
    assert "O&#x27;Neil &lt;b&gt;" in page and "<b>" not in page.replace("<b>93.8 %</b>", "")
    assert "variant_2" in page and "93.8 %" in page and "mm instead of m" in page
    # the failed answer first, then every item
    assert page.count("<tr") == 2 + 17 and page.count(">fail<") == 2 and page.count(">pass<") == 15
    assert page.index("Answers to look at again (1)") < page.index("Every item")


def test_without_out_nothing_is_written(klass, tmp_path, capsys):
    path = _write(tmp_path / "a.csv", _answers(_perfect("Ann", "variant_1", KEY_1)))
    code, out, _ = run(capsys, "grade", klass, path)
    assert code == 0 and "100 %" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "class"]


def test_write_grades_returns_the_files(klass, tmp_path):
    grades = grade(klass, _write(tmp_path / "a.csv", _answers(_perfect("Ann", "variant_1", KEY_1)
                                                               + _perfect("Ann", "variant_2", KEY_2))))
    files = write_grades(grades, tmp_path / "out")
    assert [f.name for f in files] == ["grades.csv", "items.csv", "student_Ann_variant_1.html",
                                       "student_Ann_variant_2.html"]


def test_answers_template_has_a_row_per_key_row():
    text = answers_template(_key_csv(KEY_1), "variant_7")
    rows = list(csv.reader(io.StringIO(text)))
    assert rows[0] == list(ANSWER_COLUMNS)
    assert rows[1:] == [["", "variant_7", q, "" if p is None else str(p), ""] for q, p, *_ in KEY_1]


# ----------------------------------------------------------------------------------------------
# the whole loop: linkage variants, then grade the key's own numbers
# ----------------------------------------------------------------------------------------------


def test_variants_then_grade_the_keys_numbers_scores_100(linkage_run, tmp_path, capsys):
    made = linkage_run("variants", "press_slider_crank", "--count", "2", "--seed", "1", "--out", "class")
    assert made.status == 0, made.err
    klass = made.cwd / "class"
    rows = []
    for k in (1, 2):
        key = list(csv.DictReader(io.StringIO((klass / f"variant_{k}" / "key.csv").read_text(encoding="utf-8"))))
        template = list(csv.DictReader(io.StringIO(
            (klass / f"variant_{k}" / "answers.csv").read_text(encoding="utf-8"))))
        assert [(r["quantity"], r["position"]) for r in template] == [(r["quantity"], r["position"]) for r in key]
        rows += [(f"student{k}", f"variant_{k}", r["quantity"], r["position"], r["value"]) for r in key]
    path = _write(tmp_path / "answers.csv", _answers(rows))
    code, out, err = run(capsys, "grade", klass, path, "--out", tmp_path / "grades")
    assert code == 0, err
    assert [line.split()[-2:] for line in out.splitlines()[1:3]] == [["100", "%"], ["100", "%"]]
