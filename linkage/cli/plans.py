"""``linkage plans``: the graphical method at one table position (plans of velocities and
accelerations, force polygons, Zhukovsky's lever), as JSON numbers or drawings to scale."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import InputError
from ..kinetostatics.plans import build_plans, require_crank_input
from ..model.numbers import MAX_POSITIONS
from ..report.plan_drawings import drawing_scales, write_plan_drawings
from ..report.results import forces_results
from .options import (
    CONVENTIONS,
    HelpFormatter,
    add_positions_arguments,
    add_scheme_argument,
    add_speed_arguments,
    declared_dynamics,
    input_speed,
    load_scheme,
    note,
    out,
    real,
    say,
    whole,
)


def add(sub) -> None:
    p = sub.add_parser(
        "plans", help="the graphical method: plans of velocities and accelerations, force polygons, the lever",
        formatter_class=HelpFormatter, epilog=CONVENTIONS,
        description="The plans of velocities and accelerations (vectors from a pole, group by group), the force "
                    "polygon of every Assur group and input link, and Zhukovsky's lever (the velocity plan turned "
                    "by 90 deg with the forces at their image points) at one table position, from the exact "
                    "kinematics and kinetostatics (docs/plans.md). JSON (default, on stdout): phi_deg (deg), "
                    "velocity and acceleration (point -> [x, y], m/s and m/s^2), angular_velocity (rad/s), "
                    "angular_acceleration (rad/s^2), velocity_plan, acceleration_plan, force_polygons (N, N m), "
                    "lever, lever_balancing_moment and balancing_moment (N m). svg / png: the drawings to scale "
                    "(plans, force polygons, lever, and a sheet with the mechanism), written into --out.")
    add_scheme_argument(p)
    p.add_argument("--position", "-i", metavar="I", type=whole(1, MAX_POSITIONS + 1), required=True,
                   help="the position number of the table, 1 .. N+1, as in 'linkage analyze' and 'linkage forces' "
                        "(position 1: the scheme's start, by default the output's extreme position)")
    add_positions_arguments(p)
    add_speed_arguments(p, "input angular velocity (default: the scheme's mean speed, else 1 rad/s with a note)")
    p.add_argument("--eps", metavar="RAD_S2", type=real, default=0.0,
                   help="input angular acceleration, rad/s^2 (default 0)")
    p.add_argument("--format", "-f", choices=("json", "svg", "png"), default="json",
                   help="JSON numbers on stdout (default), or the drawings as SVG or PNG files")
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="the folder to write into (created; default for drawings: the current folder); with "
                        "json the document is written to DIR/SCHEME_position_I.json instead of stdout")
    for option, what in (("--mu-v", "velocity plan, (m/s)/mm"), ("--mu-a", "acceleration plan, (m/s^2)/mm"),
                         ("--mu-f", "force polygons, N/mm")):
        p.add_argument(option, metavar="MU", type=real, default=None,
                       help=f"scale of the {what}, in every drawing of the position, the sheet's too (default: "
                            "the students' scale, 1, 2, 2.5, 4 or 5 x 10^n, that draws the longest vector 60-120 mm "
                            "long, larger where the drawing would not fit its cell of the sheet)")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    mech = load_scheme(args)
    require_crank_input(mech)
    for option, value in (("--mu-v", args.mu_v), ("--mu-a", args.mu_a), ("--mu-f", args.mu_f)):
        if value is not None and value <= 0:
            raise InputError(f"{option} {value:g}: a scale must be positive (units per mm)")
    omega, spec = input_speed(args, mech), declared_dynamics(mech)
    if omega is None and spec is not None:
        omega = spec.mean_speed
    notes = []
    if omega is None:
        omega = 1.0
        notes.append(f"scheme '{mech.name}' declares no speed and none was given: omega = 1 rad/s (the plans of "
                     "the analogs, in m/s per rad/s); give --omega or --rpm for the real speed")
        note("note", notes[-1])
    if omega == 0:
        raise InputError("--omega 0: the plans need a moving input; give a nonzero speed, rad/s")
    results = forces_results(mech, args.positions, args.start, omega, args.eps)
    say(results)
    count = len(results.motion.phi)
    if args.position > count:
        raise InputError(f"--position {args.position}: scheme '{mech.name}' has the table positions 1 to {count} "
                         f"({count - 1} steps; --positions N changes them)")
    i = args.position - 1
    failed = [f for f in results.meta["failed"] if f["position"] == args.position]
    if failed:
        raise InputError(f"--position {args.position}: scheme '{mech.name}' {failed[0]['problem']} at the input "
                         f"angle {failed[0]['input_angle_deg']:.6g} deg: it has no plans there")
    plans = build_plans(results.motion, results.reactions)
    given = {"velocity": args.mu_v, "acceleration": args.mu_a, "force": args.mu_f}
    scales = drawing_scales(plans, i, {k: v for k, v in given.items() if v is not None})
    stem = f"{mech.name}_position_{args.position}"
    if args.format != "json":
        written = write_plan_drawings(plans, i, args.out or ".", formats=(args.format,), stem=stem,
                                      scales={k: v for k, v in given.items() if v is not None})
        out("\n".join(str(path) for path in written))
        return 0
    doc = {"scheme": mech.name, "formula": results.meta["formula"], "position": args.position,
           "positions": results.meta["positions"], "direction": results.meta["direction"],
           **plans.summary(i, results.meta["direction"]), "scales": scales,
           "units": {"phi_deg": "deg", "input_angle_deg": "deg", "omega": "rad/s", "eps": "rad/s^2",
                     "velocity": "m/s", "acceleration": "m/s^2", "angular_velocity": "rad/s",
                     "angular_acceleration": "rad/s^2", "velocity_plan": "m/s", "acceleration_plan": "m/s^2",
                     "force_polygons": "N (moments N m)", "lever.forces.force": "N", "lever.forces.arm": "m/s",
                     "lever.forces.moment": "N m/s", "lever.moments.contribution": "N m/s",
                     "lever_balancing_moment": "N m", "balancing_moment": "N m",
                     "scales": "velocity (m/s)/mm, acceleration (m/s^2)/mm, force N/mm"},
           "notes": notes + list(results.notes), "conventions": "see docs/plans.md and docs/conventions.md"}
    text = json.dumps(doc, ensure_ascii=False, allow_nan=False)
    if args.out is None:
        out(text)
    else:
        path = Path(args.out) / f"{stem}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text + "\n", encoding="utf-8")
        out(str(path))
    return 0
