"""``linkage dynamics``: machine dynamics of a scheme (reduced characteristics, flywheel, the law of
motion by the course, exact or ode method, the start-up transient), and for a slide input its law
of motion over the stroke; the options that name a refused value and the notes of the ode method."""

from __future__ import annotations

import argparse
import contextlib
from dataclasses import replace

import numpy as np

from ..dynamics.equation import StartupStall, simulate
from ..dynamics.spec import override_spec
from ..dynamics.stroke import stroke_motion
from ..errors import InputError
from ..kinetostatics.friction import friction_of
from ..report.results import dynamics_results
from .options import (
    CONVENTIONS,
    HelpFormatter,
    add_columns_argument,
    add_format_argument,
    add_scheme_argument,
    add_speed_arguments,
    declared_dynamics,
    emit,
    fit,
    input_speed,
    load_scheme,
    note,
    positions,
    real,
    sense_in_words,
    start_line,
)


def add(sub) -> None:
    p = sub.add_parser(
        "dynamics", help="machine dynamics: flywheel, law of motion, reactions under real motion",
        formatter_class=HelpFormatter, epilog=CONVENTIONS,
        description="The course pipeline (docs/methods.md): reduced moments and inertia, the "
                    "constant driving moment, the flywheel for a coefficient of speed fluctuation "
                    "delta, the crank's omega(phi) and eps(phi), then the balancing moment under "
                    "that motion and the coefficient of dynamics max|M_b| / |M_d|. Methods: "
                    "'course' (Mertsalov, table positions), 'exact' (energy equation on a fine "
                    "grid, exact flywheel), 'ode' (equation of motion with the scheme's motor, "
                    "steady state by shooting; without a motor, a constant driving moment, with a "
                    "note). Inputs come from the scheme's [dynamics] section; the options override "
                    "them. Columns: i, phi_deg, reduced_moment_resistance, reduced_moment_driving "
                    "(N m), reduced_inertia (kg m^2, I_0 + I'' as declared), "
                    "reduced_inertia_derivative (kg m^2/rad), omega (rad/s), eps (rad/s^2), "
                    "balancing_moment (N m); with --transient: t (s), phi_deg, omega (rad/s).")
    add_scheme_argument(p)
    p.add_argument("--positions", "-n", metavar="N", type=positions, default=None,
                   help="N equal steps per revolution (default: the scheme's, else 12)")
    p.add_argument("--delta", metavar="D", type=real, default=None,
                   help="coefficient of speed fluctuation (default: the scheme's)")
    add_speed_arguments(p, "mean speed of the input link (default: the scheme's)")
    p.add_argument("--method", choices=("course", "exact", "ode"), default="course",
                   help="course (default), exact or ode")
    p.add_argument("--transient", action="store_true",
                   help="with --method ode: give the start-up from the scheme's initial speed "
                        "(t, phi_deg, omega at every step of the integration, over the scheme's "
                        "cycles) instead of the per-position table")
    stroke = p.add_argument_group(
        "slide inputs", "A mechanism driven by a slide (a piston, a cylinder: docs/inputs.md) moves over its "
                        "stroke once: its law of motion comes from the energy equation along the stroke. "
                        "Columns: i, s (m), t (s), v (m/s), a (m/s^2), force, reduced_force, "
                        "balancing_force (N), reduced_mass (kg); -n steps over the stroke (default 24).")
    stroke.add_argument("--force", metavar="N", type=real, default=None,
                        help="the actuator's force along +s, N (default 0: the declared loads alone)")
    stroke.add_argument("--initial-speed", metavar="M_S", type=real, default=None,
                        help="|ds/dt| at the start of the stroke, m/s (default 0: from rest)")
    p.add_argument("--friction", action="store_true",
                   help="Coulomb friction in the pairs, from the scheme's [friction] (docs/friction.md): its "
                        "reduced moment at the mean speed (column reduced_moment_friction, N m) joins the "
                        "resistance, so the driving moment, the flywheel and the motor account for it; the "
                        "summary gains friction_work (J per cycle) and cycle_efficiency")
    p.add_argument("--friction-real-speed", action="store_true",
                   help="with --friction: compute the friction's reactions under the law of motion's own "
                        "omega(phi), eps(phi) instead of the mean speed, repeating the method until the flywheel "
                        "and the driving moment settle (to 1e-6; a note says in how many rounds)")
    add_columns_argument(p)
    add_format_argument(p)
    p.set_defaults(handler=run)


def _cmd_stroke(args: argparse.Namespace, mech) -> int:
    """``linkage dynamics`` for a slide input: the law of motion over the stroke."""

    crank_only = [option for option, value in (("--delta", args.delta), ("--omega", args.omega),
                                               ("--rpm", args.rpm)) if value is not None]
    crank_only += ["--method " + args.method] if args.method != "course" else []
    crank_only += ["--transient"] if args.transient else []
    if crank_only:
        raise InputError(f"{', '.join(crank_only)}: scheme '{mech.name}' is driven by a slide (input "
                         f"'{mech.inputs[0]}'), whose dynamics is one stroke, not a cycle of a crank: give "
                         "--force N and --initial-speed M_S instead")
    force = 0.0 if args.force is None else args.force
    speed = 0.0 if args.initial_speed is None else args.initial_speed
    if speed < 0:
        raise InputError(f"--initial-speed {speed:g}: a speed is >= 0 m/s (the sense is the stroke's)")
    motion = stroke_motion(mech, force, initial_speed=speed, positions=args.positions or 24)
    columns = motion.columns()
    start, end = mech.input_range
    meta = {"scheme": mech.name, "start": f"s0 = {start:.10g} m (start of the stroke), v0 = {speed:.6g} m/s; s runs to "
                                          f"{end:.10g} m in {args.positions or 24} steps",
            "force": f"{force:.6g} N" if args.format == "table" else force,
            "stroke_time": f"{motion.t[-1]:.6g} s" if args.format == "table" else float(motion.t[-1])}
    emit(columns, args, meta, None)
    return 0


#: units of the scalar results of ``linkage dynamics`` (the ``# key: value`` lines of the table)
_SUMMARY_UNITS = {
    "driving_moment": "N m", "required_constant_inertia": "kg m^2", "flywheel_inertia": "kg m^2",
    "mean_speed_actual": "rad/s", "constant_inertia": "kg m^2",
    "exact_required_constant_inertia": "kg m^2", "exact_flywheel_inertia": "kg m^2",
    "transient_time": "s", "settling_time": "s", "initial_speed": "rad/s", "friction_work": "J",
}


def _dynamics_view(columns: dict) -> list[str]:
    """The default columns of ``linkage dynamics`` for people: the law of motion, the balancing
    moment, then the reduced characteristics, as many as fit, in table order."""
    groups = [["omega"], ["eps"], ["balancing_moment"], ["reduced_moment_resistance"], ["reduced_inertia"],
              ["reduced_moment_driving"], ["reduced_inertia_derivative"]]
    shown = set(fit(columns, ("i", "phi_deg", "t"), groups))
    return [name for name in columns if name in shown]


def run(args: argparse.Namespace) -> int:
    mech = load_scheme(args)
    if not mech.coordinate.is_angle:
        return _cmd_stroke(args, mech)
    if args.force is not None or args.initial_speed is not None:
        given = "--force" if args.force is not None else "--initial-speed"
        raise InputError(f"{given}: scheme '{mech.name}' is driven by a crank (input '{mech.inputs[0]}'); "
                         "--force and --initial-speed are for a slide input")
    if args.friction_real_speed and not args.friction:
        raise InputError("--friction-real-speed: give --friction with it (the friction it computes under the law "
                         "of motion is the scheme's [friction])")
    if args.transient and args.method != "ode":
        raise InputError(f"--transient: the start-up is a solution of the equation of motion with the "
                         f"motor: give --method ode with it (got --method {args.method})")
    declared = declared_dynamics(mech)
    spec = None
    if args.method == "ode":
        with _options_named(args):
            spec = override_spec(mech, None, args.delta, input_speed(args, mech), args.positions)
            if args.friction:
                spec = replace(spec, friction=friction_of(mech))
        if args.transient and spec.initial_speed is None:
            raise InputError(f"--transient: scheme '{mech.name}' declares no speed to start from: give "
                             "initial_rpm (or initial_speed, rad/s) in its [dynamics] section")
        first = "sizing the flywheel (exact method), then " if spec.delta is not None else ""
        then = " and integrating the start-up transient" if spec.initial_speed is not None else ""
        note("note", f"{first}shooting for the motor-driven steady state{then}; this takes a few seconds")
    with _options_named(args):
        results = dynamics_results(mech, args.method, positions=args.positions, delta=args.delta,
                                   mean_speed=input_speed(args, mech), friction=args.friction,
                                   real_speed=args.friction_real_speed)
    report, summary = results.report, dict(results.summary)
    for line in report.notes:
        note("note", line)
    if spec is not None:
        _ode_notes(mech, spec, report)
    law = report.law
    direction = law.reduced.rotation
    n = len(law.phi) - 1
    if args.transient:
        transient, stalled = _startup(mech, spec, law)
        columns = transient.columns()
        summary.update(initial_speed=spec.initial_speed)
        until = f", up to the stall at t = {stalled.t:.4g} s" if stalled is not None else ""
        start = (f"t = 0 at phi0 = {round(float(np.degrees(law.phi[0])), 10) + 0.0:.10g} deg, "
                 f"|omega| = {spec.initial_speed:.6g} rad/s; phi_deg counts from it "
                 f"{sense_in_words(direction)}, 360 per cycle, {spec.cycles} cycles{until}")
        always = ("t", "phi_deg")
    else:
        columns = results.columns
        start = start_line(mech, law.phi, declared.start if declared is not None else "extreme", n, direction)
        always = ("i", "phi_deg")
    if args.format == "table":
        in_words = {"flywheel_inertia": "none needed", "dynamic_coefficient": "undefined (see the note)"}
        shown = {"scheme": mech.name, "start": start}
        for k, v in summary.items():
            if k in ("scheme", "positions", "phi0_deg", "direction") or (v is None and k not in in_words):
                continue
            text = f"{v:.6g}" if isinstance(v, float) else in_words[k] if v is None else str(v)
            unit = _SUMMARY_UNITS.get(k) if v is not None else None
            shown[k] = f"{text} {unit}" if unit else text
        summary = shown
    emit(columns, args, summary, _dynamics_view, always=always)
    return 0


def _startup(mech, spec, law):
    """The start-up transient of ``--transient`` and its stall (None when it does not stall): a
    start-up that stalls is the motion up to the stall (the pipeline's note already said where
    and why)."""
    try:
        return simulate(mech, spec, constant_inertia=law.constant_inertia), None
    except StartupStall as stalled:
        return stalled.transient, stalled.stall


@contextlib.contextmanager
def _options_named(args):
    """A refusal of a value the user gave as an option (``delta must be ...``) names the option
    and the value as given on the command line (``--delta 5: delta must be ...``)."""
    try:
        yield
    except InputError as exc:
        text = str(exc)
        speed = ("--rpm", args.rpm) if args.rpm is not None else ("--omega", args.omega)
        for key, (option, value) in (("mean_speed", speed), ("delta", ("--delta", args.delta)),
                                     ("positions", ("--positions", args.positions))):
            if value is not None and text.startswith(key):
                raise InputError(f"{option} {value:g}: {text}") from None
        raise


def _ode_notes(mech, spec, report) -> None:
    """What the ode method assumed or found that a user must know: a constant driving moment
    when the scheme declares no motor; a steady mean speed that misses the declared one by more
    than delta."""
    law = report.law
    if spec.motor is None:
        note("note", f"scheme '{mech.name}' declares no [dynamics.motor]: --method ode drives the crank "
                     f"with a constant moment, the cycle's mean driving moment {law.driving_moment:.6g} N m, "
                     "so the steady state keeps the declared mean speed; declare a motor to use its "
                     "characteristic")
        return
    actual = law.details.get("mean_speed")
    declared = spec.mean_speed
    if actual is None or spec.delta is None:
        return
    miss = abs(actual - declared) / abs(declared)
    if miss > spec.delta:
        note("note", f"the motor's steady mean speed {actual:.4g} rad/s differs from the declared mean "
                     f"speed {declared:.4g} rad/s by {100 * miss:.3g} %, more than delta = {spec.delta:g}: "
                     "the flywheel was sized for the declared speed; check the motor's data in "
                     "[dynamics.motor] (ratio, synchronous_rpm, rated_rpm ...) or the mean speed")
