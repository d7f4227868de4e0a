"""Grading a class's answers against the answer keys of ``linkage variants`` (``linkage grade``).

A class folder holds one folder per variant (``variant_K``), each with its ``key.csv`` (columns
``quantity,position,value,unit,tolerance``, one row per quantity and position, the position empty
for a scalar) and, when present, ``key.json``, whose ``items`` give each item's significant digits
and ``floor`` (its quantity's natural scale) and may give ``other_mode`` (the value in the other
assembly mode). The students' answers are CSV files with the columns
``student,variant,quantity,position,value`` (:data:`ANSWER_COLUMNS`); :func:`answers_template`
writes the empty one each variant folder gets.

:func:`grade` checks every item of a student's variant: it passes when

    |given - expected| <= tolerance * max(|expected|, floor)

(angles in degrees compared modulo 360; ``floor`` from ``key.json``, else the largest |value| of
the quantity over the variant's positions). A failed item gets a hint when the answer is one of
the usual mistakes: the opposite sign, a factor 1000 (mm for m, kN for N), 30/pi (rpm for rad/s),
180/pi (degrees for radians), the other assembly mode's value, the value at another position; an
item the student left out fails with the hint "no answer". :func:`write_grades` writes
``grades.csv`` (one row per student and variant), ``items.csv`` (one row per item) and one HTML
page per student.

>>> key = "quantity,position,value,unit,tolerance\\nB.x,1,0.25,m,0.02\\ndriving_moment,,12.5,N m,0.02\\n"
>>> print(answers_template(key, "variant_3"), end="")
student,variant,quantity,position,value
,variant_3,B.x,1,
,variant_3,driving_moment,,
>>> hint_for(250.0, 0.25, 0.02, 0.3, "m")
'mm instead of m (given = 1000 x the key)'
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InputError

__all__ = ["ANSWER_COLUMNS", "KEY_COLUMNS", "GRADE_COLUMNS", "ITEM_COLUMNS", "DEFAULT_TOLERANCE", "Key", "KeyItem",
           "ItemGrade", "StudentGrade", "Grades", "answers_template", "read_class", "read_answers", "grade",
           "hint_for", "write_grades", "grades_csv", "items_csv", "student_page", "page_names"]

#: the columns of a student's answers, exactly
ANSWER_COLUMNS = ("student", "variant", "quantity", "position", "value")
#: the columns of a variant's ``key.csv``
KEY_COLUMNS = ("quantity", "position", "value", "unit", "tolerance")
#: the columns of ``grades.csv``: one row per student and variant
GRADE_COLUMNS = ("student", "variant", "items", "passed", "score")
#: the columns of ``items.csv``: one row per student and item of the key
ITEM_COLUMNS = ("student", "variant", "quantity", "position", "expected", "given", "relative_error", "passed",
                "hint")
#: the relative tolerance of an item whose key gives none
DEFAULT_TOLERANCE = 0.02
#: significant digits an expected value is shown with when the key gives none
DEFAULT_DIGITS = 4
#: the hint of an item the student did not answer
NO_ANSWER = "no answer"
#: at most this many problems are listed in one error
MAX_PROBLEMS = 20

_PREFIXED = {"N": "kN", "N m": "kN m", "J": "kJ"}


# ----------------------------------------------------------------------------------------------
# the key
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class KeyItem:
    """One graded item of a variant's key: a quantity at a position ('' for a scalar)."""

    quantity: str
    position: str
    value: float
    unit: str
    tolerance: float
    floor: float
    digits: int
    other_mode: float | None = None

    @property
    def scale(self) -> float:
        """What the tolerance is relative to: max(|value|, floor)."""
        return max(abs(self.value), self.floor)


@dataclass(frozen=True)
class Key:
    """A variant's answer key: its folder's name, its template and its items in key.csv's order."""

    variant: str
    template: str
    items: tuple[KeyItem, ...]

    def item(self, quantity: str, position: str) -> KeyItem | None:
        for item in self.items:
            if item.quantity == quantity and item.position == position:
                return item
        return None

    def quantities(self) -> dict[str, list[KeyItem]]:
        """The items by quantity, in key order."""
        out: dict[str, list[KeyItem]] = {}
        for item in self.items:
            out.setdefault(item.quantity, []).append(item)
        return out


def _position(text: Any) -> str:
    """A position as text: '' for a scalar, '3' for 3, 3.0, '3', ' 3 ' or '3.0'."""
    if text is None:
        return ""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return str(int(text)) if float(text).is_integer() else repr(float(text))
    text = str(text).strip()
    try:
        number = float(text)
    except ValueError:
        return text
    return str(int(number)) if math.isfinite(number) and number.is_integer() else text


def _problems(problems: list[str]) -> InputError:
    shown = problems[:MAX_PROBLEMS]
    if len(problems) > MAX_PROBLEMS:
        shown.append(f"... and {len(problems) - MAX_PROBLEMS} more problems")
    return InputError("\n".join(shown))


def _rows(text: str, where: str, columns: Sequence[str], what: str) -> tuple[list[tuple[int, dict[str, str]]], str]:
    """The rows of a CSV text with exactly ``columns`` (any order) as ``(line, {column: cell})``,
    cells stripped, blank rows left out; and the delimiter (',' or ';', for a spreadsheet that
    writes decimal commas)."""
    lines = text.splitlines()
    first = next((line for line in lines if line.strip()), None)
    if first is None:
        raise InputError(f"{where}: empty file (expected {what} with the header {','.join(columns)})")
    delimiter = ";" if ";" in first and "," not in first else ","
    reader = csv.reader(io.StringIO(text), delimiter=delimiter)
    header: list[str] | None = None
    rows = []
    for cells in reader:
        cells = [c.strip() for c in cells]
        if not any(cells):
            continue
        if header is None:
            header = [c.lower() for c in cells]
            missing = [c for c in columns if c not in header]
            unknown = [c for c in header if c not in columns]
            if missing or unknown or len(set(header)) != len(header):
                said = []
                if missing:
                    said.append(f"missing column{'s' if len(missing) > 1 else ''} {', '.join(missing)}")
                if unknown:
                    said.append(f"unknown column{'s' if len(unknown) > 1 else ''} "
                                f"{', '.join(repr(c) for c in unknown)}")
                if not said:
                    said.append("a column given twice")
                raise InputError(f"{where}, line {reader.line_num}: {'; '.join(said)} (the header of {what} is "
                                 f"exactly {','.join(columns)})")
            continue
        if len(cells) > len(header):
            if any(cells[len(header):]):
                comma = " (a decimal comma? write a decimal point)" if delimiter == "," else ""
                raise InputError(f"{where}, line {reader.line_num}: {len(cells)} cells, the header has "
                                 f"{len(header)} ({','.join(header)}){comma}")
            cells = cells[:len(header)]
        cells += [""] * (len(header) - len(cells))
        rows.append((reader.line_num, dict(zip(header, cells))))
    return rows, delimiter


def _number(text: str, delimiter: str) -> float | None:
    """A cell as a finite number, or None when it is not one (a decimal comma is read in a
    ';'-separated file; a typographic minus as '-')."""
    text = text.replace("\u2212", "-")
    for space in (" ", "\u00a0", "\u202f"):   # thousands separated by spaces: 125 000
        text = text.replace(space, "")
    if delimiter == ";":
        text = text.replace(",", ".")
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _read_key(folder: Path) -> Key:
    """The key of one variant folder: key.csv, with the digits, floors and other modes of
    key.json's items when it has them."""
    where = folder / "key.csv"
    rows, _ = _rows(where.read_text(encoding="utf-8-sig"), str(where), KEY_COLUMNS, "an answer key")
    extra: dict[tuple[str, str], Mapping[str, Any]] = {}
    template, digits = "", DEFAULT_DIGITS
    if (folder / "key.json").is_file():
        try:
            data = json.loads((folder / "key.json").read_text(encoding="utf-8"))
        except ValueError as exc:
            raise InputError(f"{folder / 'key.json'}: not a JSON file ({exc})") from None
        template = str(data.get("template", ""))
        if isinstance(data.get("digits"), int):
            digits = data["digits"]
        for entry in data.get("items", []) or []:
            if isinstance(entry, Mapping) and "quantity" in entry:
                extra[(str(entry["quantity"]), _position(entry.get("position")))] = entry
    parsed, problems, seen = [], [], {}
    for line, row in rows:
        quantity, position = row["quantity"], _position(row["position"])
        value = _number(row["value"], ",")
        tolerance = _number(row["tolerance"], ",") if row["tolerance"] else DEFAULT_TOLERANCE
        if not quantity:
            problems.append(f"{where}, line {line}: no quantity")
        elif value is None:
            problems.append(f"{where}, line {line}: value {row['value']!r} of {quantity} is not a number")
        elif tolerance is None or tolerance < 0:
            problems.append(f"{where}, line {line}: tolerance {row['tolerance']!r} of {quantity} is not a "
                            "number >= 0")
        elif (quantity, position) in seen:
            problems.append(f"{where}, line {line}: {quantity} at position {position or '(none)'} is given "
                            f"twice (lines {seen[(quantity, position)]} and {line})")
        else:
            seen[(quantity, position)] = line
            parsed.append((quantity, position, value, row["unit"], tolerance))
    if problems:
        raise _problems(problems)
    natural: dict[str, float] = {}
    for quantity, _, value, _, _ in parsed:
        natural[quantity] = max(natural.get(quantity, 0.0), abs(value))
    items = []
    for quantity, position, value, unit, tolerance in parsed:
        entry = extra.get((quantity, position), {})
        floor = entry.get("floor")
        other = entry.get("other_mode")
        item_digits = entry.get("digits")
        items.append(KeyItem(
            quantity, position, value, unit, tolerance,
            floor=abs(float(floor)) if _finite(floor) else natural[quantity],
            digits=item_digits if isinstance(item_digits, int) and item_digits > 0 else digits,
            other_mode=float(other) if _finite(other) else None))
    return Key(folder.name, template, tuple(items))


def _finite(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _variant_number(name: str) -> int:
    match = re.fullmatch(r"variant_(\d+)", name)
    return int(match.group(1)) if match else 10**9


def read_class(folder: str | Path) -> dict[str, Key]:
    """The keys of a class folder written by ``linkage variants``, by variant folder name
    (``variant_1`` ...; every sub-folder with a ``key.csv``). A variant folder itself (one with a
    ``key.csv``) is a class of one variant."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such folder (the class folder written by 'linkage variants')")
    if (folder / "key.csv").is_file():
        folders = [folder]
    else:
        folders = sorted((p for p in folder.iterdir() if (p / "key.csv").is_file()),
                         key=lambda p: (_variant_number(p.name), p.name))
    if not folders:
        raise InputError(f"{folder}: no variant folder with a key.csv in it (the class folder written by "
                         "'linkage variants', holding variant_1/key.csv ...)")
    return {p.name: _read_key(p) for p in folders}


# ----------------------------------------------------------------------------------------------
# the answers
# ----------------------------------------------------------------------------------------------


def answers_template(key_csv: str, variant: str) -> str:
    """The ``answers.csv`` a variant folder gets: the header ``student,variant,quantity,position,value``
    and one row per row of ``key_csv`` (the text of the variant's key.csv) with the variant's
    folder name filled in and the student and value empty."""
    rows, _ = _rows(key_csv, "key.csv", KEY_COLUMNS, "an answer key")
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(ANSWER_COLUMNS)
    for _, row in rows:
        writer.writerow(["", variant, row["quantity"], _position(row["position"]), ""])
    return buffer.getvalue()


@dataclass(frozen=True)
class Answer:
    """One answer: where it was read (file, line), whose, and the value given."""

    file: str
    line: int
    student: str
    variant: str
    quantity: str
    position: str
    value: float


def _answer_files(answers: str | Path) -> list[Path]:
    path = Path(answers)
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.suffix.lower() == ".csv" and p.is_file())
        if not files:
            raise InputError(f"{path}: no .csv file in the folder (the students' answers, columns "
                             f"{','.join(ANSWER_COLUMNS)})")
        return files
    if not path.is_file():
        raise InputError(f"{path}: no such file or folder (the students' answers: a CSV file or a folder of them)")
    return [path]


def read_answers(answers: str | Path, keys: Mapping[str, Key]) -> tuple[list[Answer], list[tuple[str, str]],
                                                                         list[str]]:
    """The answers of a CSV file or of every ``*.csv`` of a folder, checked against the keys.

    Returns the answers given (a row with a value), every (student, variant) with a row, and
    notes (a file without any answer). A student's cell left empty is the one name the file
    gives (a student may write it once), else the file's name without ``.csv``; a row without a
    value is an item not answered. A variant may be written ``3`` for ``variant_3``.

    Raises
    ------
    InputError
        Naming the file, the line and the value of every problem: an empty file, missing or
        unknown columns, an unknown variant, an unknown quantity or position of that variant, a
        value that is not a number, an item given twice.
    """
    given: list[Answer] = []
    students: dict[tuple[str, str], None] = {}
    notes: list[str] = []
    problems: list[str] = []
    seen: dict[tuple[str, str, str, str], str] = {}
    names = ", ".join(list(keys)[:3]) + (f" ... {list(keys)[-1]}" if len(keys) > 3 else "")
    for path in _answer_files(answers):
        where = str(path)
        try:
            rows, delimiter = _rows(path.read_text(encoding="utf-8-sig"), where, ANSWER_COLUMNS, "answers")
        except InputError as exc:
            problems.append(str(exc))
            continue
        except UnicodeDecodeError:
            problems.append(f"{where}: not a UTF-8 text file (save it as CSV UTF-8)")
            continue
        answered = 0
        named = {row["student"] for _, row in rows if row["student"]}
        anonymous = named.pop() if len(named) == 1 else path.stem   # who a row without a name is
        for line, row in rows:
            at = f"{where}, line {line}"
            if not row["student"] and not row["value"]:
                continue  # an unfilled row of the template
            student = row["student"] or anonymous
            variant = row["variant"]
            if variant.isdigit():
                variant = f"variant_{int(variant)}"
            key = keys.get(variant)
            if key is None:
                problems.append(f"{at}: unknown variant {row['variant']!r} (the class folder has {names})"
                                if row["variant"] else f"{at}: no variant (a variant folder's name such as "
                                                       f"{next(iter(keys))})")
                continue
            quantity, position = row["quantity"], _position(row["position"])
            positions = [item.position for item in key.items if item.quantity == quantity]
            if not positions:
                problems.append(f"{at}: unknown quantity {quantity!r} for {variant} (see its key.csv or answers.csv)")
                continue
            if position not in positions:
                if positions == [""]:
                    problems.append(f"{at}: {quantity} is a single value: leave its position empty, got "
                                    f"{row['position']!r}")
                else:
                    problems.append(f"{at}: unknown position {row['position']!r} of {quantity} for {variant} "
                                    f"(positions {_span(positions)})")
                continue
            students[(student, variant)] = None
            if not row["value"]:
                continue
            value = _number(row["value"], delimiter)
            if value is None:
                problems.append(f"{at}: value {row['value']!r} of {quantity} is not a number")
                continue
            ident = (student, variant, quantity, position)
            if ident in seen:
                problems.append(f"{at}: {student} gives {quantity}{f' at position {position}' if position else ''} "
                                f"twice (first at {seen[ident]})")
                continue
            seen[ident] = f"{where}, line {line}"
            given.append(Answer(where, line, student, variant, quantity, position, value))
            answered += 1
        if not answered:
            notes.append(f"{where}: no answers in it (every value empty)")
    if problems:
        raise _problems(problems)
    return given, list(students), notes


def _span(positions: Sequence[str]) -> str:
    numbers = [int(p) for p in positions if p.isdigit()]
    if len(numbers) == len(positions) and numbers == list(range(numbers[0], numbers[0] + len(numbers))):
        return f"{numbers[0]} .. {numbers[-1]}"
    return ", ".join(positions)


# ----------------------------------------------------------------------------------------------
# grading
# ----------------------------------------------------------------------------------------------


def _difference(given: float, expected: float, unit: str) -> float:
    """given - expected; for an angle in degrees, the difference wrapped into [-180, 180]."""
    d = given - expected
    if unit == "deg":
        d = (d + 180.0) % 360.0 - 180.0
    return d


def _passes(given: float, expected: float, tolerance: float, scale: float, unit: str) -> bool:
    return abs(_difference(given, expected, unit)) <= tolerance * scale


def _factors(unit: str) -> list[tuple[float, str]]:
    """(factor, mistake): given = factor x the key when the student made the mistake (the unit
    as key.csv writes it; an empty or unknown unit is tried for every angle mistake)."""
    plain = unit in ("", "1")
    out: list[tuple[float, str]] = []
    if unit == "m" or unit.startswith("m/"):
        out.append((1000.0, f"mm{unit[1:]} instead of {unit}"))
    elif unit == "N m":
        out.append((1000.0, "N mm instead of N m"))
    else:
        out.append((1000.0, "a unit prefix (a factor 1000)"))
    if unit in _PREFIXED:
        out.append((0.001, f"{_PREFIXED[unit]} instead of {unit}"))
    else:
        out.append((0.001, "a unit prefix (a factor 1/1000)"))
    if unit.startswith("rad/s") or plain:
        out.append((30 / math.pi, "rpm instead of rad/s"))
        out.append((math.pi / 30, "rpm and rad/s mixed up"))
        out.append((180 / math.pi, "degrees instead of radians"))
    if unit == "deg" or plain:
        out.append((math.pi / 180, "radians instead of degrees"))
    elif "/rad" in unit and not unit.startswith("rad/"):
        out.append((math.pi / 180, "per degree instead of per radian"))
    return out


_FACTOR_TEXT = {1000.0: "1000", 0.001: "1/1000", 30 / math.pi: "30/pi", math.pi / 30: "pi/30",
                180 / math.pi: "180/pi", math.pi / 180: "pi/180"}


def hint_for(given: float, expected: float, tolerance: float, floor: float, unit: str = "", *,
             others: Mapping[str, float] | None = None, other_mode: float | None = None) -> str:
    """The usual mistake a failed answer ``given`` looks like, or '' when it looks like none.

    A mistake is named when the answer, undone of it, would pass (the pass rule with the same
    tolerance and floor) and the value it leads to is told apart from the right one (the two
    pass bands do not overlap): the opposite sign (for an angle in degrees also 180 deg off), a
    factor 1000 or 1/1000 (mm for m, kN for N), 30/pi (rpm for rad/s), 180/pi (degrees for
    radians), each also with the opposite sign; then the value of the other assembly mode
    (``other_mode``) and the value of the same quantity at another position (``others``:
    {position: value})."""
    scale = max(abs(expected), floor)
    if _passes(given, expected, tolerance, scale, unit):
        return ""
    band = tolerance * scale

    def apart(candidate: float, width: float) -> bool:
        return abs(_difference(candidate, expected, unit)) > band + width

    if unit == "deg":
        for candidate, text in ((-expected, "wrong sign"), (expected + 180.0, "the opposite direction (180 deg off)")):
            if apart(candidate, band) and _passes(given, candidate, tolerance, scale, unit):
                return text
    elif apart(-expected, band) and _passes(given, -expected, tolerance, scale, ""):
        return "wrong sign"
    for factor, mistake in _factors(unit):
        for sign in (1.0, -1.0):
            f = sign * factor
            width = band * factor
            if apart(f * expected, width) and abs(given - f * expected) <= width:
                said = f"{'-' if sign < 0 else ''}{_FACTOR_TEXT[factor]}"
                return f"{'wrong sign and ' if sign < 0 else ''}{mistake} (given = {said} x the key)"
    if other_mode is not None and apart(other_mode, band) and _passes(given, other_mode, tolerance, scale, unit):
        return "the other assembly mode"
    best = None
    for position, value in (others or {}).items():
        if _passes(given, value, tolerance, scale, unit):
            error = abs(_difference(given, value, unit))
            if best is None or error < best[0]:
                best = (error, position)
    if best is not None:
        return f"the value at position {best[1]} (wrong position?)"
    return ""


@dataclass(frozen=True)
class ItemGrade:
    """One item of a student's variant, graded. ``given`` and ``relative_error`` are None for an
    item not answered; ``relative_error`` = |given - expected| / max(|expected|, floor), the
    number the pass rule compares with ``tolerance``."""

    student: str
    variant: str
    quantity: str
    position: str
    unit: str
    expected: float
    given: float | None
    relative_error: float | None
    tolerance: float
    digits: int
    passed: bool
    hint: str


@dataclass(frozen=True)
class StudentGrade:
    """A student's score on a variant: items of the key, items passed, score in percent."""

    student: str
    variant: str
    template: str
    items: int
    passed: int

    @property
    def score(self) -> float:
        return 100.0 * self.passed / self.items if self.items else 0.0


@dataclass(frozen=True)
class Grades:
    """The graded answers of a class: every item of every student (in key order, students in
    order of name), the students' scores, and notes (files without answers)."""

    items: tuple[ItemGrade, ...]
    students: tuple[StudentGrade, ...]
    notes: tuple[str, ...] = ()

    def of(self, student: StudentGrade) -> list[ItemGrade]:
        """The items of one student's variant."""
        return [i for i in self.items if i.student == student.student and i.variant == student.variant]


def grade(folder: str | Path, answers: str | Path) -> Grades:
    """Grade the answers (a CSV file or a folder of CSV files with the columns
    ``student,variant,quantity,position,value``) against the keys of the class folder ``folder``
    (the folder of ``linkage variants``): every item of each student's variant, passed or not,
    with its relative error and a hint for a usual mistake; an item not answered fails with the
    hint "no answer".

    Raises
    ------
    InputError
        A folder without keys, or answers naming an unknown variant, quantity or position, a
        value that is not a number, missing columns, an empty file (the message names the file,
        the line and the value).
    """
    keys = read_class(folder)
    given, students, notes = read_answers(answers, keys)
    values = {(a.student, a.variant, a.quantity, a.position): a.value for a in given}
    students.sort(key=lambda sv: (sv[0].casefold(), sv[0], _variant_number(sv[1]), sv[1]))
    items: list[ItemGrade] = []
    summary: list[StudentGrade] = []
    for student, variant in students:
        key = keys[variant]
        by_quantity = key.quantities()
        passed = 0
        for item in key.items:
            value = values.get((student, variant, item.quantity, item.position))
            if value is None:
                items.append(ItemGrade(student, variant, item.quantity, item.position, item.unit, item.value, None,
                                       None, item.tolerance, item.digits, False, NO_ANSWER))
                continue
            error = abs(_difference(value, item.value, item.unit))
            relative = error / item.scale if item.scale > 0 else (0.0 if error == 0 else math.inf)
            ok = error <= item.tolerance * item.scale
            hint = "" if ok else hint_for(
                value, item.value, item.tolerance, item.floor, item.unit, other_mode=item.other_mode,
                others={o.position: o.value for o in by_quantity[item.quantity] if o.position != item.position})
            passed += ok
            items.append(ItemGrade(student, variant, item.quantity, item.position, item.unit, item.value, value,
                                   relative, item.tolerance, item.digits, ok, hint))
        summary.append(StudentGrade(student, variant, key.template, len(key.items), passed))
    return Grades(tuple(items), tuple(summary), tuple(notes))


# ----------------------------------------------------------------------------------------------
# the files
# ----------------------------------------------------------------------------------------------


def _score_text(score: float) -> str:
    return f"{round(score, 1):g}"


def _csv_text(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buffer.getvalue()


def _full(x: float | None) -> str:
    return "" if x is None else repr(float(x)) if math.isfinite(x) else "inf"


def grades_csv(grades: Grades) -> str:
    """``grades.csv``: student, variant, items, passed, score (percent)."""
    return _csv_text(GRADE_COLUMNS, ((s.student, s.variant, s.items, s.passed, _score_text(s.score))
                                     for s in grades.students))


def items_csv(grades: Grades) -> str:
    """``items.csv``: every graded item (passed: 1 or 0; relative_error to 4 significant digits)."""
    return _csv_text(ITEM_COLUMNS, (
        (i.student, i.variant, i.quantity, i.position, _full(i.expected), _full(i.given),
         "" if i.relative_error is None else "inf" if math.isinf(i.relative_error) else f"{i.relative_error:.4g}",
         int(i.passed), i.hint) for i in grades.items))


def _significant(x: float, digits: int) -> str:
    """``x`` rounded to ``digits`` significant digits, written without an exponent between 1e-4
    and 1e9 (0.0123, 125000, 4.500)."""
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    exponent = math.floor(math.log10(abs(float(f"{x:.{digits}g}"))))
    if not -4 <= exponent < 9:
        return f"{x:.{digits}g}"
    decimals = digits - 1 - exponent
    return f"{x:.{decimals}f}" if decimals >= 0 else f"{round(x, decimals):.0f}"


_STYLE = """\
body { font-family: 'DejaVu Sans', Arial, sans-serif; margin: 24px; color: #222; }
h1 { font-size: 22px; margin: 0 0 4px 0; }
p.meta { margin: 2px 0 14px 0; color: #444; }
p.score { font-size: 18px; margin: 0 0 14px 0; }
h2 { font-size: 16px; margin: 16px 0 6px 0; }
table { border-collapse: collapse; font-size: 13px; }
td.hint { min-width: 12em; }
th, td { border: 1px solid #bbb; padding: 3px 8px; }
th { background: #eee; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.fail td { background: #fdecea; }
td.ok { color: #1b6e20; font-weight: bold; }
td.no { color: #b3261e; font-weight: bold; }
p.rule { font-size: 12px; color: #555; margin-top: 12px; }
"""


#: the columns of a student's page
_HEADS = ("quantity", "position", "unit", "expected", "given", "error", "tolerance", "result", "hint")
#: plain-text spellings and their symbols on a page for people
_SYMBOLS = (("^2", "\u00b2"), ("kg m", "kg\u00b7m"), ("N m", "N\u00b7m"), ("30/pi", "30/\u03c0"),
            ("pi/30", "\u03c0/30"), ("180/pi", "180/\u03c0"), ("pi/180", "\u03c0/180"),
            (" x the key", " \u00d7 the key"))


def _percent(fraction: float, tolerance: float | None = None) -> str:
    """A relative error in percent to 2 significant digits, without an exponent (0.41 %, 37 %, 86000 %;
    below 0.01 %: &lt; 0.01 %); with more digits where 2 would not tell it from ``tolerance``
    (2.04 %, not 2 %, for an error that fails a tolerance of 2 %)."""
    if math.isinf(fraction):
        return "&infin;"
    for digits in range(2, 8):
        pct = float(f"{100 * fraction:.{digits}g}")
        if tolerance is None or (pct > 100 * tolerance) == (fraction > tolerance):
            break
    if 0 < pct < 0.01:
        return "&lt; 0.01 %"
    return f"{pct:g} %" if pct < 100 else f"{pct:.0f} %"


def _for_people(text: str) -> str:
    for plain, symbol in _SYMBOLS:
        text = text.replace(plain, symbol)
    return text


def _table(items: Sequence[ItemGrade], tolerances: bool) -> str:
    """The HTML table of ``items`` (with a column of tolerances when ``tolerances``)."""
    e = html.escape
    heads = [h for h in _HEADS if tolerances or h != "tolerance"]
    rows = [f"<tr>{''.join(f'<th>{h}</th>' for h in heads)}</tr>"]
    for i in items:
        given = "" if i.given is None else f"{i.given:.10g}"
        error = "" if i.relative_error is None else _percent(i.relative_error, i.tolerance)
        numbers = [e(_significant(i.expected, i.digits)), e(given), error]
        if tolerances:
            numbers.append(f"{100 * i.tolerance:g} %")
        result = '<td class="ok">pass</td>' if i.passed else '<td class="no">fail</td>'
        rows.append(f"<tr{'' if i.passed else ' class=fail'}><td>{e(i.quantity)}</td>"
                    f'<td class="num">{e(i.position)}</td><td>{e(_for_people(i.unit))}</td>'
                    + "".join(f'<td class="num">{c}</td>' for c in numbers)
                    + f'{result}<td class="hint">{e(_for_people(i.hint))}</td></tr>')
    return "<table>\n" + "\n".join(rows) + "\n</table>"


def student_page(student: StudentGrade, items: Sequence[ItemGrade]) -> str:
    """One student's graded page (HTML, self-contained): the variant, the score, the answers that
    failed (when any) and a table of every item with expected, given, error, pass/fail and hint."""
    e = html.escape
    wrong = [i for i in items if not i.passed and i.given is not None]
    missing = sum(1 for i in items if i.given is None)
    template = f", template {e(student.template)}" if student.template else ""
    shared = {i.tolerance for i in items}
    tolerances = len(shared) > 1
    if len(shared) == 1:
        template += f"; tolerance {100 * shared.pop():g} % for every item"
    parts = [f"<h1>{e(student.student)}</h1>", f'<p class="meta">{e(student.variant)}{template}</p>',
             (f'<p class="score">Score: <b>{_score_text(student.score)} %</b> ({student.passed} of {student.items} '
              f"items passed{f'; {missing} not answered' if missing else ''})</p>")]
    if wrong:
        parts += [f"<h2>Answers to look at again ({len(wrong)})</h2>", _table(wrong, tolerances), "<h2>Every item</h2>"]
    parts.append(_table(items, tolerances))
    body = "\n".join(parts)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{e(student.student)}: {e(student.variant)}</title>
<style>
{_STYLE}</style>
</head>
<body>
{body}
<p class="rule">An item passes when |given &minus; expected| &le; tolerance &times; max(|expected|, floor),
floor being the quantity's largest magnitude over the positions; the error is |given &minus; expected|
relative to that same scale (angles in degrees are compared modulo 360).</p>
</body>
</html>
"""


def _file_name(name: str) -> str:
    return re.sub(r"[^\w.-]+", "_", name, flags=re.UNICODE).strip("._") or "student"


def page_names(grades: Grades) -> list[str]:
    """The page of each student of ``grades.students``: ``student_<name>.html`` (with the variant
    when a name has several; characters a file name cannot hold as '_')."""
    counts: dict[str, int] = {}
    for s in grades.students:
        counts[s.student] = counts.get(s.student, 0) + 1
    names, used = [], set()
    for s in grades.students:
        stem = f"student_{_file_name(s.student)}" + (f"_{_file_name(s.variant)}" if counts[s.student] > 1 else "")
        name, k = f"{stem}.html", 2
        while name.casefold() in used:
            name, k = f"{stem}_{k}.html", k + 1
        used.add(name.casefold())
        names.append(name)
    return names


def write_grades(grades: Grades, out: str | Path) -> list[Path]:
    """Write ``grades.csv``, ``items.csv`` and one ``student_<name>.html`` per student into the
    folder ``out`` (created); return the files written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    files = [(out / "grades.csv", grades_csv(grades)), (out / "items.csv", items_csv(grades))]
    for student, name in zip(grades.students, page_names(grades)):
        files.append((out / name, student_page(student, grades.of(student))))
    for path, text in files:
        path.write_text(text, encoding="utf-8")
    return [path for path, _ in files]
