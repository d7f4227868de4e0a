"""``linkage forces``: the kinetostatics table of a scheme (the reactions in every pair and the
balancing moment, or force for a slide input, at N equal steps of the input)."""

from __future__ import annotations

import argparse

import numpy as np

from ..report.results import declared_rotation, forces_results
from .options import (
    CONVENTIONS,
    HelpFormatter,
    add_columns_argument,
    add_format_argument,
    add_positions_arguments,
    add_scheme_argument,
    add_speed_arguments,
    emit,
    fit,
    input_speed,
    leading,
    load_scheme,
    real,
    say,
    start_line,
)


def add(sub) -> None:
    p = sub.add_parser(
        "forces", help="kinetostatics: pair reactions and the balancing moment",
        formatter_class=HelpFormatter, epilog=CONVENTIONS,
        description="Reactions in every pair and the balancing moment on the input link at N "
                    "equal steps of phi, from the scheme's loads (gravity, external forces and "
                    "diagrams) and the inertia loads of the given motion (docs/methods.md). "
                    "Columns: i, phi_deg, balancing_moment (N m, CCW positive; with several input "
                    "links the first's, and balancing_moment.L for each further input link L), and for each pair "
                    "K: K.R (N) and K.angle_deg, the magnitude and direction of the force R[a, b] "
                    "that link b exerts on link a for the pair's links = [a, b]; K.Rx, K.Ry (N) "
                    "and, for prismatic pairs, K.M (N m, about the slider's point). The table for "
                    "people shows the balancing moment and as many magnitudes and directions as "
                    "fit. A scheme driven by a slide (a piston, a cylinder) is analysed over its "
                    "declared stroke: its columns are i, s (the slide, m), balancing_force (N, along "
                    "+s) and the pairs'; --omega and --eps are then its speed (m/s) and acceleration "
                    "(m/s^2).")
    add_scheme_argument(p)
    add_positions_arguments(p)
    add_speed_arguments(p, "input angular velocity (default: the scheme's mean speed, else "
                           "none: a static analysis)")
    p.add_argument("--eps", metavar="RAD_S2", type=real, default=0.0,
                   help="input angular acceleration, rad/s^2 (default 0); for a slide input, m/s^2")
    p.add_argument("--friction", action="store_true",
                   help="Coulomb friction in the pairs, from the scheme's [friction] (docs/friction.md): "
                        "balancing_moment then holds the balancing moment with friction (same sign convention), "
                        "and the table gains efficiency (useful over driving power), power_lost (W), per pair "
                        "K.Mf (N m, revolute) or K.Ff (N, prismatic) and K.power_lost (W); the works and the "
                        "efficiency of one turn at constant speed are printed below the table (JSON: cycle). "
                        "Positions where the mechanism self-locks are NaN, with a note naming the pair")
    add_columns_argument(p)
    add_format_argument(p)
    p.set_defaults(handler=run)


def _forces_view(columns: dict) -> list[str]:
    """The default columns of ``linkage forces`` for people: the balancing moment, then the
    magnitude of every reaction, then their directions, as many as fit, in table order."""
    pairs = [name[:-2] for name in columns if name.endswith(".R")]
    moments = [name for name in columns if name.startswith("balancing_") or name in ("efficiency", "power_lost")]
    losses = [[name] for name in columns if name.endswith((".Mf", ".Ff"))]
    groups = [moments] + [[f"{k}.R"] for k in pairs] + losses + [[f"{k}.angle_deg"] for k in pairs]
    shown = set(fit(columns, leading(columns), groups))
    return [name for name in columns if name in shown]


def run(args: argparse.Namespace) -> int:
    mech = load_scheme(args)
    results = forces_results(mech, args.positions, args.start, input_speed(args, mech), args.eps,
                             friction=args.friction)
    say(results)
    meta = results.meta
    cycle = meta.get("cycle")
    if args.format == "table":
        omega, phi = meta["omega"], results.motion.phi
        direction = declared_rotation(mech) if not omega else int(np.sign(omega))
        unit = mech.coordinate.unit
        speed = "none (static analysis)" if omega is None else f"{omega:.6g} {unit}/s"
        meta = {"scheme": mech.name, "start": start_line(mech, phi, meta["start"], meta["positions"], direction),
                "omega": speed, "eps": f"{args.eps:.6g} {unit}/s^2", "convention": meta["convention"],
                "virtual_power_residual_max": meta["virtual_power_residual_max"]}
        if args.friction:
            meta["friction"] = ", ".join(f"{k}: f = {v['f']:g}" + (f", r = {v['radius']:g} m" if "radius" in v else "")
                                         + (f", block {v['length']:g} m" if "length" in v else "")
                                         for k, v in results.meta["friction"].items()) or "none declared (f = 0)"
            if cycle:
                meta["cycle"] = (f"one turn at constant speed ({cycle['samples']} steps): driving work "
                                 f"{cycle['driving_work']:.6g} {cycle['unit']}, useful {cycle['useful_work']:.6g}, "
                                 f"friction {cycle['friction_work']:.6g}; efficiency {cycle['efficiency']:.4f}")
    emit(results.columns, args, meta, _forces_view)
    return 0
