"""``linkage variants``: course assignments, N feasible variants of a template (drawn from a seed or
given in a teacher's table), each written with its sheet and answer key; needs the 'report' extra."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..course.template import load_template
from ..course.variants import select_variants, write_variants
from ..errors import InputError
from ..report.folder import require_report_extra
from .options import EXIT_INPUT, note, out, progress, whole


def add(sub) -> None:
    p = sub.add_parser(
        "variants", help="course assignments: N feasible variants of a template, each with its sheet and key",
        description="Draw N distinct feasible variants of a template (docs/templates.md; shipped: "
                    "press_slider_crank, shaper_two_dyad, press_crank_rocker) reproducibly from a seed, "
                    "or take a teacher's table of given variants (--table: an infeasible row is an "
                    "error naming it, unless --skip-infeasible), and write one folder per variant, "
                    "variant_1 ... variant_N: "
                    "scheme.toml, sheet.pdf (the drawing to scale, the data, what to compute), "
                    "key.json (the answer key: the fields of 'linkage dynamics scheme.toml --format "
                    "json' with the same values, plus the parameters and the checks) and the CSV "
                    "tables; plus index.csv (units in the header: 'crank [m]'), index.pdf and "
                    "selection.json (how many draws each "
                    "feasibility rule rejected). The same seed gives byte-identical files. Needs the "
                    "'report' extra: pip install \"linkage[report]\".")
    p.add_argument("template", metavar="TEMPLATE",
                   help="a shipped template name or the path of a template file")
    p.add_argument("--count", "-n", metavar="N", type=whole(1, 100_000), default=None,
                   help="variants to make (default: 10; with --table: every row)")
    p.add_argument("--seed", "-s", metavar="S", type=whole(0, 2**63 - 1), default=None,
                   help="seed of the draws (required without --table)")
    p.add_argument("--table", metavar="CSV", default=None,
                   help="a CSV of given variants, one row per variant (columns: the free parameters, "
                        "optionally 'variant'); a row that breaks a rule of [template.require] is an "
                        "error naming its line, the rule and the value measured")
    p.add_argument("--skip-infeasible", action="store_true",
                   help="with --table: leave the infeasible rows out (a note names each row and why) "
                        "instead of refusing the table")
    p.add_argument("--out", "-o", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--workers", "-j", metavar="K", type=whole(1, 1024), default=1,
                   help="build the variants in K worker processes (default 1)")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="build the variants on a Dask distributed cluster at ADDRESS (tcp://host:8786); "
                        "needs the 'dask' extra: pip install \"linkage[dask]\"")
    p.add_argument("--max-draws", metavar="D", type=whole(1, 10_000_000), default=None,
                   help="stop drawing after D draws (default: max(1000, 50 N))")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    require_report_extra("linkage variants")
    if args.table is None and args.seed is None:
        raise InputError("give --seed S for the draws (or --table CSV of given variants)")
    if args.table is not None and not Path(args.table).is_file():
        raise InputError(f"--table {args.table}: no such file")
    if args.skip_infeasible and args.table is None:
        raise InputError("--skip-infeasible applies to a table of given variants (--table CSV) only: "
                         "drawn variants that are infeasible are always drawn again")
    template = load_template(args.template)
    count = args.count if args.count is not None else (100_000 if args.table is not None else 10)
    selection = select_variants(template, count, args.seed, given=args.table, skip_infeasible=args.skip_infeasible,
                                max_draws=args.max_draws, progress=progress("drawing feasible variants"))
    for line in selection.lines():
        note("note", line)
    if not selection.variants:
        raise InputError(f"template '{template.name}': no feasible variant (see the notes above)")
    folders = write_variants(selection, args.out, workers=args.workers, scheduler=args.scheduler,
                             progress=progress("building variants"))
    out(f"{Path(args.out) / 'index.csv'}: {len(folders)} variants")
    return 0 if len(selection.variants) == count or args.table is not None else EXIT_INPUT
