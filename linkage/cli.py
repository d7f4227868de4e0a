"""The ``linkage`` command line.

    linkage schemes                                   list the shipped schemes
    linkage analyze SCHEME [--positions N] [--start extreme|max|min|DEG] [--format table|csv|json]
    linkage forces SCHEME [--positions N] [--omega RAD_S | --rpm RPM] [--eps RAD_S2]
                          [--start ...] [--format table|csv|json]
    linkage dynamics SCHEME [--positions N] [--delta D] [--rpm R | --omega W]
                            [--method course|exact|ode] [--format table|json]

Every subcommand is one ``_add_<name>(subparsers)`` function that registers its parser and sets
``handler`` to a function ``(args) -> int``; add a new command by writing such a pair and listing
the registering function in :data:`COMMANDS`. Tables go to stdout through
:func:`linkage.report.format_columns`; notes, warnings and errors go to stderr. Errors of the
input (:class:`linkage.LinkageError`, ``ValueError``) print one line per problem and exit with
status 2, without a traceback; warnings are printed as ``linkage: warning: ...`` lines (never as
Python's warning text); an unexpected exception (a bug) prints one ``internal error`` line and
exits with status 1.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import warnings
from typing import Callable, Sequence

import numpy as np

from . import __version__
from .errors import InputError, LinkageError, SchemeError
from .extremes import table_angles
from .kinematics import analyze, structure_of
from .motors import RPM
from .model import MAX_ANGLE_DEG, MAX_MAGNITUDE, MAX_POSITIONS
from .report import FORMATS, format_columns
from .scheme import load, section_of, shipped_schemes

__all__ = ["main", "COMMANDS"]

PROG = "linkage"

#: exit status of errors in the user's input (same as argparse's usage errors)
EXIT_INPUT = 2
#: exit status of an unexpected exception (a bug of the library)
EXIT_INTERNAL = 1


def _declared_dynamics(mech):
    """The scheme's dynamics inputs (parsed once, with the scheme), or None."""
    return section_of(mech, "dynamics")


def _rotation(mech) -> int:
    """Order of table positions: the sign of the scheme's declared mean speed, else +1."""
    spec = _declared_dynamics(mech)
    return spec.rotation if spec is not None else 1


# ----------------------------------------------------------------------------------------------
# output helpers
# ----------------------------------------------------------------------------------------------


def _write(stream, text: str) -> None:
    """Write ``text``; characters the stream cannot encode (e.g. '→' on a cp1252 pipe) are
    replaced instead of failing."""
    try:
        stream.write(text)
    except UnicodeEncodeError:
        enc = getattr(stream, "encoding", None) or "ascii"
        stream.write(text.encode(enc, errors="replace").decode(enc))


def _out(text: str) -> None:
    _write(sys.stdout, text if text.endswith("\n") else text + "\n")


def _note(kind: str, message: str) -> None:
    """One ``linkage: <kind>: ...`` line on stderr per line of ``message``."""
    for line in str(message).splitlines() or [""]:
        _write(sys.stderr, f"{PROG}: {kind}: {line}\n")


def _error_lines(exc: BaseException) -> list[str]:
    if isinstance(exc, SchemeError):
        return [p for problem in exc.problems for p in str(problem).splitlines()]
    return str(exc).splitlines() or [type(exc).__name__]


# ----------------------------------------------------------------------------------------------
# linkage schemes
# ----------------------------------------------------------------------------------------------


def _add_schemes(sub) -> None:
    p = sub.add_parser("schemes", help="list the shipped schemes",
                       description="List the schemes shipped with the library: name, structural "
                                   "formula, description.")
    p.set_defaults(handler=_cmd_schemes)


def _cmd_schemes(args: argparse.Namespace) -> int:
    rows, status = [], 0
    for name in shipped_schemes():
        try:
            mech = load(name)
            rows.append((name, structure_of(mech).formula, mech.description))
        except LinkageError as exc:  # a broken shipped file must not hide the others
            for line in _error_lines(exc):
                _note("error", line)
            rows.append((name, "?", "(cannot be loaded, see the error above)"))
            status = EXIT_INPUT
    if rows:
        w_name = max(len(r[0]) for r in rows)
        w_formula = max(len(r[1]) for r in rows)
        _out("\n".join(f"{n.ljust(w_name)}  {f.ljust(w_formula)}  {d}".rstrip() for n, f, d in rows))
    return status


# ----------------------------------------------------------------------------------------------
# linkage analyze
# ----------------------------------------------------------------------------------------------


def _positions(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of positions, got {text!r}") from None
    if not 1 <= n <= MAX_POSITIONS:
        raise argparse.ArgumentTypeError(f"the number of positions must be in [1, {MAX_POSITIONS}], got {n}")
    return n


def _start(text: str) -> str | float:
    if text in ("extreme", "max", "min"):
        return text
    try:
        deg = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected 'extreme', 'max', 'min' or an angle in degrees, got {text!r}") from None
    if not (math.isfinite(deg) and abs(deg) <= MAX_ANGLE_DEG):
        raise argparse.ArgumentTypeError(f"the start angle must be a finite number of degrees with "
                                         f"|x| <= {MAX_ANGLE_DEG:g}, got {text!r}")
    return deg


def _real(text: str) -> float:
    """A finite number within the declared range of every number (|x| <= 1e50)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and abs(value) <= MAX_MAGNITUDE):
        raise argparse.ArgumentTypeError(f"expected a finite number with |x| <= {MAX_MAGNITUDE:g}, got {text!r}")
    return value


def _add_scheme_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("scheme", metavar="SCHEME",
                   help="a shipped scheme name (see 'linkage schemes') or the path of a .toml file")


def _add_positions_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--positions", "-n", metavar="N", type=_positions, default=12,
                   help="N equal steps per revolution; rows are positions 1..N+1 (default 12)")
    p.add_argument("--start", metavar="extreme|DEG", type=_start, default="extreme",
                   help="position 1: 'extreme' (default) = the extreme position of the scheme's "
                        "output that starts the cycle ('max' / 'min' pick one), or an input angle "
                        "in degrees")


def _add_format_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--format", "-f", choices=FORMATS, default="table",
                   help="aligned text for people (default), CSV at full precision, or JSON")


def _add_analyze(sub) -> None:
    p = sub.add_parser(
        "analyze", help="kinematics table: positions, velocity and acceleration analogs",
        description="Positions and first / second transfer functions (analogs, d/dphi) of every "
                    "named point, moving link angle and prismatic slide, at N equal steps of the "
                    "input angle phi (METHOD section 1). Columns: phi_deg; P.x P.y P.x' P.y' "
                    "P.x'' P.y''; L.theta L.theta' L.theta''; K.s K.s' K.s'' (SI units: m, rad).")
    _add_scheme_argument(p)
    _add_positions_arguments(p)
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_analyze)


def _table_positions(mech, n: int, start: str | float, direction: int) -> tuple[np.ndarray, str | float]:
    """Input angles of the table (rad) and the start actually used."""
    if isinstance(start, str) and mech.output is None:
        _note("note", f"scheme '{mech.name}' declares no output, so it has no extreme position: "
                      "the table starts at phi = 0 deg (use --start DEG to choose)")
        start = 0.0
    try:
        return table_angles(mech, n, start, direction), start
    except InputError as exc:  # e.g. the output has no extreme position
        if isinstance(start, str):
            raise InputError(f"{exc} (choose position 1 with --start DEG)") from None
        raise


def _cmd_analyze(args: argparse.Namespace) -> int:
    mech = load(args.scheme)
    direction = _rotation(mech)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        phi, start = _table_positions(mech, args.positions, args.start, direction)
        motion = analyze(mech, phi, order=2, on_failure="mask")
        columns = motion.columns()
    if not isinstance(start, str):
        # label the rows with the angles as given (30, 60, ...), not their degrees(radians(...))
        # round trip (29.999999999999996, ...); the difference is at the last digit
        columns["phi_deg"] = start + direction * np.arange(len(phi)) * 360.0 / args.positions
    failed = _report_failures(motion)
    for w in caught:
        if issubclass(w.category, RuntimeWarning) and failed:
            continue  # numerical noise at the masked positions, reported above
        _note("warning", str(w.message))
    phi0_deg = float(columns["phi_deg"][0])
    meta = {
        "scheme": mech.name,
        "description": mech.description,
        "formula": structure_of(mech).formula,
        "positions": args.positions,
        "start": start,
        "phi0_deg": phi0_deg,
        "direction": direction,
        "units": "SI (m, rad); phi_deg in degrees; ' and '' are d/dphi and d2/dphi2",
        "failed": failed,
    }
    if args.format == "table":
        meta = {k: meta[k] for k in ("scheme", "formula")}
        where = ""
        if isinstance(start, str):
            which = mech.output.start if start == "extreme" else start
            where = f" ({which} of {mech.output.quantity})"
        shown = round(phi0_deg, 10) + 0.0  # no round-off noise such as 5e-14 deg for 0
        meta["start"] = f"phi0 = {shown:.10g} deg{where}, {args.positions} steps per revolution"
    _out(format_columns(columns, args.format, meta=meta))
    return 0


def _report_failures(motion) -> list[dict]:
    """Warn on stderr about positions that cannot be assembled or are singular."""
    from assur.base import CANNOT_ASSEMBLE, SINGULAR

    failed = []
    phi_deg = np.degrees(motion.phi)
    for code, what, blank in ((CANNOT_ASSEMBLE, "cannot be assembled", "values are empty (nan)"),
                              (SINGULAR, "is singular", "analogs are empty (nan)")):
        where = np.flatnonzero(motion.status == code)
        if len(where):
            shown = ", ".join(f"{phi_deg[i]:.6g}" for i in where)
            _note("warning", f"mechanism '{motion.mechanism.name}' {what} at phi (deg) = {shown}: "
                             f"{blank} in those rows")
            for i in where:
                entry = {"position": int(i) + 1, "phi_deg": float(phi_deg[i]), "problem": what}
                if code == SINGULAR:  # the least conditioned group: its distance to the singularity
                    worst = min(motion.conditioning.items(), key=lambda kv: np.nan_to_num(kv[1][i], nan=2.0))
                    entry.update(group=worst[0], conditioning=float(worst[1][i]))
                failed.append(entry)
    failed.sort(key=lambda f: f["position"])
    return failed


# ----------------------------------------------------------------------------------------------
# linkage forces
# ----------------------------------------------------------------------------------------------


def _add_speed_arguments(p: argparse.ArgumentParser, what: str) -> None:
    speed = p.add_mutually_exclusive_group()
    speed.add_argument("--omega", metavar="RAD_S", type=_real,
                       help=f"{what}, rad/s, signed (negative: clockwise)")
    speed.add_argument("--rpm", metavar="RPM", type=_real, help=f"{what}, rpm, signed")


def _speed(args) -> float | None:
    if args.rpm is not None:
        return args.rpm * RPM
    return args.omega


def _add_forces(sub) -> None:
    p = sub.add_parser(
        "forces", help="kinetostatics: pair reactions and the balancing moment",
        description="Reactions in every pair and the balancing moment on the input link at N "
                    "equal steps of phi, from the scheme's loads (gravity, external forces and "
                    "diagrams) and the inertia loads of the given motion (METHOD section 5). "
                    "Columns: phi_deg, balancing_moment (N m), and for each pair K: K.R (N) and "
                    "K.angle_deg, the force R[a, b] that link b exerts on link a for the pair's "
                    "links = [a, b]. JSON rows also carry K.Rx, K.Ry and, for prismatic pairs, "
                    "K.M (N m, about the slider's point).")
    _add_scheme_argument(p)
    _add_positions_arguments(p)
    _add_speed_arguments(p, "input angular velocity (default: the scheme's mean speed, else "
                            "none: a static analysis)")
    p.add_argument("--eps", metavar="RAD_S2", type=_real, default=0.0,
                   help="input angular acceleration, rad/s^2 (default 0)")
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_forces)


def _cmd_forces(args: argparse.Namespace) -> int:
    from .kinetostatics import solve_reactions, virtual_power_residual

    mech = load(args.scheme)
    omega = _speed(args)
    if omega is None and _declared_dynamics(mech) is not None:
        omega = _declared_dynamics(mech).mean_speed
    if omega is None and args.eps != 0:
        _note("note", "no speed given: omega = 0 with the given eps")
        omega = 0.0
    direction = _rotation(mech) if not omega else int(np.sign(omega))
    phi, start = _table_positions(mech, args.positions, args.start, direction)
    motion = analyze(mech, phi, order=2, omega=omega, eps=args.eps, on_failure="mask")
    failed = _report_failures(motion)
    ends = np.zeros(len(phi), bool)
    ends[-1] = True
    reactions = solve_reactions(motion, ends=ends)
    for note in reactions.notes:
        _note("note", note)
    residual = virtual_power_residual(reactions)
    columns = reactions.columns(full=args.format == "json")
    meta = {"scheme": mech.name, "formula": structure_of(mech).formula,
            "omega": omega, "eps": args.eps, "positions": args.positions, "start": start,
            "convention": "K.R = |R[a,b]|, the force link b exerts on link a (pair links = [a, b])",
            "virtual_power_residual_max": float(np.nanmax(residual)) if np.isfinite(residual).any() else None,
            "failed": failed, "notes": list(reactions.notes)}
    if args.format == "table":
        meta = {k: meta[k] for k in ("scheme", "omega", "eps", "virtual_power_residual_max")}
    _out(format_columns(columns, args.format, meta=meta))
    return 0


# ----------------------------------------------------------------------------------------------
# linkage dynamics
# ----------------------------------------------------------------------------------------------


def _add_dynamics(sub) -> None:
    p = sub.add_parser(
        "dynamics", help="machine dynamics: flywheel, law of motion, reactions under real motion",
        description="The course pipeline (METHOD section 6): reduced moments and inertia, the "
                    "constant driving moment, the flywheel for a coefficient of speed fluctuation "
                    "delta, the crank's omega(phi) and eps(phi), then the balancing moment under "
                    "that motion and the coefficient of dynamics max|M_b| / |M_d|. Methods: "
                    "'course' (Mertsalov, table positions), 'exact' (energy equation on a fine "
                    "grid, exact flywheel), 'ode' (equation of motion with the scheme's motor, "
                    "steady state by shooting). Inputs come from the scheme's [dynamics] section; "
                    "the options override them.")
    _add_scheme_argument(p)
    p.add_argument("--positions", "-n", metavar="N", type=_positions, default=None,
                   help="N equal steps per revolution (default: the scheme's, else 12)")
    p.add_argument("--delta", metavar="D", type=_real, default=None,
                   help="coefficient of speed fluctuation (default: the scheme's)")
    _add_speed_arguments(p, "mean speed of the input link (default: the scheme's)")
    p.add_argument("--method", choices=("course", "exact", "ode"), default="course",
                   help="course (default), exact or ode")
    p.add_argument("--format", "-f", choices=("table", "json"), default="table",
                   help="aligned text (default) or JSON")
    p.set_defaults(handler=_cmd_dynamics)


def _cmd_dynamics(args: argparse.Namespace) -> int:
    from .dynamics import run_dynamics

    mech = load(args.scheme)
    if args.method == "ode":
        _note("note", "sizing the flywheel (exact method), then shooting for the motor-driven "
                      "steady state and integrating the start-up transient; this takes a few seconds")
    report = run_dynamics(mech, args.method, positions=args.positions, delta=args.delta,
                          mean_speed=_speed(args))
    for note in report.notes:
        _note("note", note)
    summary = {"scheme": mech.name, **report.summary()}
    if args.format == "json":
        _out(format_columns(report.columns(), "json", meta=summary))
    else:
        in_words = {"flywheel_inertia": "none needed", "dynamic_coefficient": "undefined (see the note)"}
        shown = {k: (f"{v:.6g}" if isinstance(v, float) else in_words[k] if v is None else v)
                 for k, v in summary.items() if v is not None or k in in_words}
        _out(format_columns(report.columns(), "table", meta=shown))
    return 0


# ----------------------------------------------------------------------------------------------
# the parser and main
# ----------------------------------------------------------------------------------------------

#: functions that register one subcommand each, in the order ``--help`` lists them
COMMANDS: list[Callable] = [_add_schemes, _add_analyze, _add_forces, _add_dynamics]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Planar linkage analysis: Assur groups, exact kinematics, "
                               "kinetostatics and machine dynamics.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in COMMANDS:
        register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors (status 2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else EXIT_INPUT)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return args.handler(args)
        except (LinkageError, ValueError) as exc:  # ValueError: a bad argument found by numpy / scipy
            for line in _error_lines(exc):
                _note("error", line)
            return EXIT_INPUT
        except BrokenPipeError:  # e.g. `linkage analyze ... | head`: the reader left, not an error
            try:
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, sys.stdout.fileno())
            except (OSError, ValueError, AttributeError):
                pass
            return 0
        except Exception as exc:  # a bug of the library: one line, no traceback
            _note("error", f"internal error ({type(exc).__name__}: {exc}); please report it with the "
                           "command line that caused it")
            return EXIT_INTERNAL
        finally:
            _report_warnings(caught)


def _report_warnings(caught) -> None:
    """The library's warnings as ``linkage: warning:`` lines; floating-point warnings of numpy
    (overflow, invalid value ...) as one line in the library's words."""
    numerical = False
    for w in caught:
        if issubclass(w.category, RuntimeWarning):
            numerical = True
        else:
            _note("warning", str(w.message))
    if numerical:
        _note("warning", "a floating-point overflow or invalid value occurred in the computation: "
                         "check the results")
