"""``linkage report``: a complete analysis of a scheme written into one folder (tables, pictures,
animation, an HTML page); needs the 'report' extra."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..report.folder import require_report_extra, write_report
from .options import add_scheme_argument, load_scheme, note, out, progress


def add(sub) -> None:
    p = sub.add_parser(
        "report", help="a complete analysis folder: tables, pictures, animation, an HTML page",
        description="Write a complete analysis of a scheme into a folder: the CSV and JSON tables of "
                    "'analyze', 'forces' and (with a [dynamics] section) 'dynamics'; PNG and SVG "
                    "pictures (the mechanism to scale, kinematic diagrams, balancing moment, "
                    "hodographs of reactions, reduced moments and work, energy-inertia diagram, "
                    "flywheel, omega and eps two ways, start-up with the motor); animation.gif, one "
                    "revolution; and index.html, one page with the data, the structural formula, the "
                    "results and every picture. Pictures the scheme's data does not allow are left "
                    "out with a note. With --friction the forces and the dynamics include the scheme's "
                    "[friction], and friction.csv and friction.png/svg (the power lost in each pair and "
                    "the efficiency) are added. Needs the 'report' extra: pip install \"linkage[report]\".")
    add_scheme_argument(p)
    p.add_argument("--out", "-o", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--friction", action="store_true",
                   help="Coulomb friction in the pairs from the scheme's [friction] (docs/friction.md): the "
                        "forces and the dynamics include it, friction.csv holds the efficiency and the power "
                        "lost per pair at each position, friction.png/svg draws them")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    require_report_extra()
    mech = load_scheme(args)
    report = write_report(mech, args.out, progress=progress("report"), friction=args.friction)
    for line in report.notes:
        note("note", line)
    out(f"{Path(args.out) / 'index.html'}: {len(report.pictures)} pictures, {len(report.files)} files")
    return 0
