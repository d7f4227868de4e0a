"""``linkage sheets``: the course project's drawing sheets (kinematics, kinetostatics, dynamics)
to scale, as PDF, DXF and SVG."""

from __future__ import annotations

import argparse
import importlib.util

from ..course.project.frame import TitleInfo
from ..course.project.model import PAPERS
from ..course.project.sheets import write_project_sheets
from ..errors import InputError
from ..report.folder import ReportExtraMissing, require_report_extra
from ..model.numbers import MAX_POSITIONS
from .options import (CONVENTIONS, HelpFormatter, add_scheme_argument, add_speed_arguments, input_speed, load_scheme,
                      note, out, whole)

#: the formats the sheets are written in
SHEET_FORMATS = ("pdf", "dxf", "svg")


def add(sub) -> None:
    p = sub.add_parser(
        "sheets", help="the course project's drawing sheets to scale (PDF, DXF, SVG)",
        formatter_class=HelpFormatter, epilog=CONVENTIONS,
        description="Write the drawing sheets of a course project for the scheme: kinematics (structural "
                    "diagram, the mechanism in its table positions at a standard scale, plans of velocities and "
                    "accelerations, diagrams of the output, plan against analytic values), kinetostatics (each "
                    "Assur group apart with its forces, force polygons, Zhukovsky's lever, M_b two ways) and "
                    "dynamics (useful resistance, reduced moments, works, energy, reduced inertia, the "
                    "energy-inertia diagram with its tangents, the flywheel's dimensions), each with a title "
                    "block and a table of scales (docs/sheets.md). A sheet whose data the scheme does not hold "
                    "is left out with a note naming the key to add. PDF and SVG need the 'report' extra, DXF "
                    "needs ezdxf (in the same extra): pip install \"linkage[report]\".")
    add_scheme_argument(p)
    p.add_argument("--out", "-o", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--position", "-i", metavar="I", type=whole(1, MAX_POSITIONS + 1), default=None,
                   help="the table position the plans, polygons and groups apart are drawn at, 1 .. N as in "
                        "'linkage analyze' (default: where the output moves fastest; position 1 is an extreme "
                        "position, where its velocity is 0)")
    p.add_argument("--format", "-f", metavar="LIST", default="pdf,dxf",
                   help="comma-separated formats among pdf, dxf, svg (default pdf,dxf)")
    add_speed_arguments(p, "input angular velocity for the kinetostatics sheet (default: the scheme's mean speed)")
    p.add_argument("--paper", choices=tuple(k for k in PAPERS if k != "A4"), default="A1",
                   help="the paper size, landscape (default A1, 841 x 594 mm)")
    for option, what in (("--student", "the student's name"), ("--group", "the student's group"),
                         ("--variant", "the assignment's variant")):
        p.add_argument(option, metavar="TEXT", default="", help=f"{what}, for the title block (default blank)")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    formats = tuple(f.strip().lower() for f in args.format.split(",") if f.strip())
    unknown = [f for f in formats if f not in SHEET_FORMATS]
    if unknown or not formats:
        raise InputError(f"--format {args.format!r}: choose among {', '.join(SHEET_FORMATS)} (comma-separated)")
    require_report_extra("linkage sheets")
    if "dxf" in formats and importlib.util.find_spec("ezdxf") is None:
        raise ReportExtraMissing("linkage sheets --format dxf needs ezdxf, in the 'report' extra: "
                                 "pip install \"linkage[report]\" (or --format pdf,svg)")
    mech = load_scheme(args)
    title = TitleInfo(scheme=mech.name, variant=args.variant, student=args.student, group=args.group)
    written, notes = write_project_sheets(mech, args.out, args.position, formats, args.paper, title,
                                          omega=input_speed(args, mech))
    for line in notes:
        note("note", line)
    out("\n".join(str(path) for path in written))
    return 0
