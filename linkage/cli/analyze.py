"""``linkage analyze``: the kinematics table of a scheme (positions and analogs of every point,
link angle and slide at N equal steps of the input), with its default view for people."""

from __future__ import annotations

import argparse

from ..report.results import declared_rotation, kinematics_results
from .options import (
    CONVENTIONS,
    HelpFormatter,
    add_columns_argument,
    add_format_argument,
    add_positions_arguments,
    add_scheme_argument,
    emit,
    fit,
    leading,
    load_scheme,
    say,
    start_line,
)


def add(sub) -> None:
    p = sub.add_parser(
        "analyze", help="kinematics table: positions, velocity and acceleration analogs",
        formatter_class=HelpFormatter, epilog=CONVENTIONS,
        description="Positions and first / second transfer functions (analogs) of every "
                    "named point, moving link angle and prismatic slide, at N equal steps of the "
                    "input angle; the analogs are d/dpsi, per rad turned from position 1 in the "
                    "direction of rotation (psi = phi_deg in rad; d/ds for a slide input), "
                    "docs/conventions.md. Columns: i, phi_deg; P.x P.y P.x' P.y' "
                    "P.x'' P.y''; L.theta L.theta' L.theta''; K.s K.s' K.s'' (m, rad). The table "
                    "for people shows the absolute input angle, the scheme's output and the "
                    "moving links and slides with their analogs, as many as fit.")
    add_scheme_argument(p)
    add_positions_arguments(p)
    add_columns_argument(p)
    add_format_argument(p)
    p.set_defaults(handler=run)


def _analyze_view(mech):
    """The default columns of ``linkage analyze`` for people: the absolute input angle, the
    output with its analogs, each other moving link's angle and each slide with their analogs,
    then the coordinates of the moving points, as many as fit."""
    def view(columns: dict) -> list[str]:
        triple = lambda q: [q, q + "'", q + "''"]  # noqa: E731
        groups = [[f"{link}.theta" for link in mech.inputs]]
        groups += [[f"{link}.theta'", f"{link}.theta''"] for link in mech.inputs[1:]]
        if mech.output is not None:
            groups.append(triple(mech.output.quantity))
        groups += [triple(f"{link}.theta") for link in mech.moving_links if link not in mech.inputs]
        groups += [triple(name) for name in columns if name.endswith(".s")]
        moving = [p for p in mech.point_names if mech.point_link(p) != mech.frame]
        groups += [[f"{p}.x", f"{p}.y"] for p in moving]
        return fit(columns, leading(columns), groups, skip_repeats=True)
    return view


def run(args: argparse.Namespace) -> int:
    mech = load_scheme(args)
    results = kinematics_results(mech, args.positions, args.start)
    say(results)
    meta = results.meta
    if args.format == "table":
        phi = results.motion.phi
        meta = {"scheme": mech.name, "formula": meta["formula"],
                "start": start_line(mech, phi, meta["start"], meta["positions"], declared_rotation(mech)),
                "analogs": meta["analogs"]}
    emit(results.columns, args, meta, _analyze_view(mech))
    return 0
