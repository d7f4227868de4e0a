"""The ``linkage`` command line.

    linkage schemes                                   list the shipped schemes
    linkage analyze SCHEME [--positions N] [--start extreme|max|min|DEG] [--format table|csv|json]

Every subcommand is one ``_add_<name>(subparsers)`` function that registers its parser and sets
``handler`` to a function ``(args) -> int``; add a new command by writing such a pair and listing
the registering function in :data:`COMMANDS`. Tables go to stdout through
:func:`linkage.report.format_columns`; notes, warnings and errors go to stderr. Errors of the
input (:class:`linkage.LinkageError`, ``ValueError``) print one line per problem and exit with
status 2, without a traceback.
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
from .errors import LinkageError, SchemeError
from .extremes import table_angles
from .kinematics import analyze, structure_of
from .report import FORMATS, format_columns
from .scheme import load, shipped_schemes

__all__ = ["main", "COMMANDS"]

PROG = "linkage"

#: exit status of errors in the user's input (same as argparse's usage errors)
EXIT_INPUT = 2


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
    if n < 1:
        raise argparse.ArgumentTypeError(f"the number of positions must be >= 1, got {n}")
    return n


def _start(text: str) -> str | float:
    if text in ("extreme", "max", "min"):
        return text
    try:
        deg = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected 'extreme', 'max', 'min' or an angle in degrees, got {text!r}") from None
    if not math.isfinite(deg):
        raise argparse.ArgumentTypeError(f"the start angle must be finite, got {text!r}")
    return deg


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


def _table_positions(mech, n: int, start: str | float) -> tuple[np.ndarray, str | float]:
    """Input angles of the table (rad) and the start actually used."""
    if isinstance(start, str) and mech.output is None:
        _note("note", f"scheme '{mech.name}' declares no output, so it has no extreme position: "
                      "the table starts at phi = 0 deg (use --start DEG to choose)")
        start = 0.0
    direction = 1  # sign of omega; schemes do not declare the sense of rotation yet
    return table_angles(mech, n, start, direction), start


def _cmd_analyze(args: argparse.Namespace) -> int:
    mech = load(args.scheme)
    phi, start = _table_positions(mech, args.positions, args.start)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        motion = analyze(mech, phi, order=2, on_failure="mask")
        columns = motion.columns()
    failed = _report_failures(motion)
    for w in caught:
        if issubclass(w.category, RuntimeWarning) and failed:
            continue  # numerical noise at the masked positions, reported above
        _note("warning", str(w.message))
    meta = {
        "scheme": mech.name,
        "description": mech.description,
        "formula": structure_of(mech).formula,
        "positions": args.positions,
        "start": start,
        "phi0_deg": float(np.degrees(phi[0])),
        "direction": 1,
        "units": "SI (m, rad); phi_deg in degrees; ' and '' are d/dphi and d2/dphi2",
        "failed": failed,
    }
    if args.format == "table":
        meta = {k: meta[k] for k in ("scheme", "formula")}
        meta["start"] = f"phi0 = {np.degrees(phi[0]):.7g} deg ({start}), {args.positions} steps"
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
            failed += [{"position": int(i) + 1, "phi_deg": float(phi_deg[i]), "problem": what}
                       for i in where]
    failed.sort(key=lambda f: f["position"])
    return failed


# ----------------------------------------------------------------------------------------------
# the parser and main
# ----------------------------------------------------------------------------------------------

#: functions that register one subcommand each, in the order ``--help`` lists them
COMMANDS: list[Callable] = [_add_schemes, _add_analyze]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Planar linkage analysis: Assur groups, exact kinematics.")
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
    try:
        return args.handler(args)
    except (LinkageError, ValueError) as exc:
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
