"""``linkage grade``: a class's answers checked against the answer keys of ``linkage variants``,
a score per student, and with ``--out`` the gradebook (grades.csv, items.csv) and one HTML page
per student."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..course.grading import grade, write_grades
from .options import note, out


def add(sub) -> None:
    p = sub.add_parser(
        "grade", help="grade a class's answers against the keys of 'linkage variants'",
        description="Check the students' answers against the answer keys of a class folder written "
                    "by 'linkage variants' (docs/grading.md): ANSWERS is a CSV file, or a folder of "
                    "them, with the columns student,variant,quantity,position,value (the answers.csv "
                    "of each variant folder, filled in). An item passes when |given - expected| <= "
                    "tolerance * max(|expected|, floor), with the key's tolerance and floor; a failed "
                    "item gets a hint for the usual mistakes (sign, mm for m, kN for N, rpm for rad/s, "
                    "degrees for radians, the other assembly mode, the value at another position), "
                    "an item left out counts as failed ('no answer'). Prints each student's score; "
                    "--out DIR writes grades.csv (student,variant,items,passed,score), items.csv "
                    "(student,variant,quantity,position,expected,given,relative_error,passed,hint) "
                    "and one page per student, student_<name>.html.")
    p.add_argument("folder", metavar="FOLDER", help="the class folder written by 'linkage variants'")
    p.add_argument("answers", metavar="ANSWERS", help="the answers: a CSV file or a folder of CSV files")
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="write grades.csv, items.csv and the students' pages into DIR (created)")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    grades = grade(args.folder, args.answers)
    for line in grades.notes:
        note("note", line)
    rows = [("student", "variant", "items", "passed", "score")]
    rows += [(s.student, s.variant, str(s.items), str(s.passed), f"{round(s.score, 1):g} %") for s in grades.students]
    widths = [max(len(r[k]) for r in rows) for k in range(5)]
    lines = ["  ".join(c.ljust(w) if k < 2 else c.rjust(w) for k, (c, w) in enumerate(zip(r, widths))).rstrip()
             for r in rows]
    if not grades.students:
        note("note", f"{args.answers}: no student's answers to grade")
    out("\n".join(lines))
    if args.out is not None:
        files = write_grades(grades, args.out)
        out(f"{Path(args.out) / 'grades.csv'}: {len(grades.students)} students, {len(files)} files")
    return 0
