"""``linkage enumerate``: every R/P assignment of a scheme's pairs, each kept one with a geometry
that runs a full turn, as a table and (``--out``) as scheme files."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import InputError
from ..report import format_columns
from ..research import COLUMN_UNITS, CRANK_FACTORS, DEFAULT_OMEGA, MIN_CONDITIONING, enumerate_chain
from .options import PROG, add_format_argument, add_scheme_argument, load_scheme, note, out, real


def add(sub) -> None:
    p = sub.add_parser(
        "enumerate", help="every R/P assignment of a scheme's pairs, each as a scheme that runs a full turn",
        description="Enumerate the pair kinds of a scheme's chain (docs/enumerate.md): every assignment of "
                    "R or P (with the guide on either link) to its pairs but the input's, kept when it "
                    "decomposes into groups the library solves (the dyads RRR, RRP, RPR, PRP, RPP and the "
                    "class-III triad in closed form, any other group by Newton's method), the others listed "
                    "with the reason (--rejected). Each kept combination gets the scheme's own geometry "
                    "(those with a traced group only with --newton, else 'not searched'); where it does not run "
                    "a full turn (assembled, regular, conditioning at "
                    f"least {MIN_CONDITIONING:g}, no change point), a shorter crank "
                    f"({', '.join(f'{f:g}' for f in CRANK_FACTORS[1:])} of the scheme's) and three "
                    "further reference positions are tried. Columns: id (e.g. A=R,B=P3,C=R: B "
                    "prismatic with its guide on link 3), formula, full_turn, crank_factor, "
                    "reference_deg (deg), output, stroke (m, or deg for a link's swing), stroke_unit, "
                    "min_transmission_angle_deg (deg), peak_balancing_moment (N m, the largest |M_b| "
                    "over a turn at --omega under gravity and inertia), note. --out DIR writes "
                    "DIR/<id>.toml for every combination that runs a full turn (loadable by 'linkage "
                    "analyze DIR/<id>.toml'), DIR/combinations.csv and DIR/rejected.csv.")
    add_scheme_argument(p)
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="write the schemes and the tables into DIR (created)")
    p.add_argument("--omega", metavar="RAD_S", type=real, default=DEFAULT_OMEGA,
                   help=f"input speed of the balancing moment, rad/s, signed (default {DEFAULT_OMEGA:g})")
    p.add_argument("--newton", action="store_true",
                   help="also search a full-turn geometry for the combinations with a group solved by Newton's "
                        "method (slow: about 1-2 s per trial, minutes for a six-bar); without it they are listed "
                        "as 'not searched'")
    p.add_argument("--rejected", action="store_true",
                   help="list the rejected assignments and why, instead of the table")
    add_format_argument(p)
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    def progress(iterable, total=None):
        try:
            from tqdm import tqdm
        except ImportError:  # the bar is a nicety of the report extra
            return iterable
        return tqdm(iterable, total=total, desc=f"{PROG}: combinations", unit="combination", file=sys.stderr,
                    disable=None, leave=False, delay=1.0)

    if args.omega == 0.0:
        raise InputError("--omega 0: the balancing moment needs a nonzero speed, rad/s")
    found = enumerate_chain(load_scheme(args), omega=args.omega, newton=args.newton, progress=progress)
    if args.out is not None:
        found.write(args.out)
    running = sum(c.full_turn is True for c in found.combinations)
    meta = {"scheme": found.source, "omega": args.omega,
            "assignments": len(found.combinations) + len(found.rejected), "solvable": len(found.combinations),
            "full_turn": running, "rejected": len(found.rejected)}
    if args.rejected:
        columns, units = found.rejected_columns(), {}
    else:
        columns, units = found.columns(), COLUMN_UNITS
    if args.format == "json":
        meta["rejected_list"] = [{"id": r.id, "reason": r.reason} for r in found.rejected]
        meta["references_deg"] = list(found.references_deg)
    if not len(columns["id"]):
        note("note", f"scheme '{found.source}': no {'rejected' if args.rejected else 'solvable'} assignment")
    if args.format == "table":
        columns.pop("note", None)
        skipped = sum(c.full_turn is None for c in found.combinations)
        unsearched = f"; {skipped} with a traced group not searched, see --newton" if skipped else ""
        meta = {"scheme": found.source,
                "assignments": f"{meta['assignments']}: {meta['solvable']} decompose into solvable groups "
                               f"({running} run a full turn{unsearched}), {meta['rejected']} rejected (see --rejected)",
                "balancing moment": f"peak |M_b| over a turn at omega = {args.omega:g} rad/s, gravity and "
                                    "inertia of the scheme's masses"}
        if args.rejected:  # one line each: the reasons are too long for a column
            text = "".join(f"# {k}: {v}\n" for k, v in meta.items())
            text += "".join(f"{i}: {reason}\n" for i, reason in zip(columns["id"], columns["reason"]))
        else:
            text = format_columns(columns, "table", meta=meta, units=units) if len(columns["id"]) else ""
            text += "".join(f"# {c.id}: {c.note}\n" for c in found.combinations if c.note and c.full_turn is not None)
        out(text or f"# scheme: {found.source}")
    else:
        out(format_columns(columns, args.format, meta=meta if args.format == "json" else None, units=units)
            if len(columns["id"]) else ",".join(columns))
    if args.out is not None:
        note("note", f"{Path(args.out)}: {running} schemes, combinations.csv, rejected.csv")
    return 0
