"""The ``linkage`` command line.

    linkage schemes                                   list the shipped schemes
    linkage analyze SCHEME [--positions N] [--start extreme|max|min|DEG] [--columns LIST]
                           [--format table|csv|json]
    linkage forces SCHEME [--positions N] [--omega RAD_S | --rpm RPM] [--eps RAD_S2]
                          [--start ...] [--columns LIST] [--format table|csv|json]
    linkage dynamics SCHEME [--positions N] [--delta D] [--rpm R | --omega W]
                            [--method course|exact|ode] [--transient] [--columns LIST]
                            [--format table|csv|json]
    linkage report SCHEME --out DIR                   tables and pictures in one folder
    linkage variants TEMPLATE ...                     course assignments from a template
    linkage enumerate SCHEME [--out DIR]              every R/P assignment of the chain's pairs
    linkage plans SCHEME --position I [--omega W | --rpm R] [--eps E] [--format json|svg|png]
                         [--out DIR]                 plans, force polygons, Zhukovsky's lever

Every scheme argument takes ``--input-law LINK:LAW`` for the further inputs of a mechanism with
several (docs/inputs.md).

Every subcommand is one ``_add_<name>(subparsers)`` function that registers its parser and sets
``handler`` to a function ``(args) -> int``; add a new command by writing such a pair and listing
the registering function in :data:`COMMANDS`. Tables go to stdout through
:func:`linkage.report.format_columns`: CSV and JSON carry every column, the table for people a
default selection at most :data:`TABLE_WIDTH` characters wide (frame points left out), and
``--columns`` chooses the columns in every format (:data:`CONVENTIONS` says what they mean).
Defaults follow the scheme: positions, start, speed and loads declared in it. Notes, warnings
and errors go to stderr, each note once per run. Errors of the
input (:class:`linkage.LinkageError`, ``ValueError``) print one line per problem and exit with
status 2, without a traceback; warnings are printed as ``linkage: warning: ...`` lines (never as
Python's warning text); an unexpected exception (a bug) prints one ``internal error`` line and
exits with status 1.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import sys
import warnings
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..course.template import load_template
from ..course.variants import select_variants, write_variants
from ..dynamics.motors import RPM
from ..dynamics.pipeline import _override, simulate
from ..dynamics.stroke import stroke_motion
from ..errors import InputError, LinkageError, SchemeError
from ..kinetostatics.plans import build_plans, require_crank_input
from ..model.input_laws import InputLaw, table_problems
from ..model.mechanism import MAX_ANGLE_DEG, MAX_MAGNITUDE, MAX_POSITIONS
from ..model.scheme import load, section_of, shipped_schemes
from ..report import FORMATS, format_columns
from ..report.folder import require_report_extra, write_report
from ..report.plan_drawings import drawing_scales, write_plan_drawings
from ..report.results import (
    JSON_CONVENTIONS,
    NUMERICAL_WARNING,
    InputRange,
    declared_rotation,
    dynamics_results,
    forces_results,
    kinematics_results,
)
from ..report.tables import select_columns, table_width, units_of
from ..research.enumeration import COLUMN_UNITS, CRANK_FACTORS, DEFAULT_OMEGA, MIN_CONDITIONING, enumerate_chain
from ..structure import structure_of
from ..version import __version__

__all__ = ["main", "COMMANDS"]

PROG = "linkage"

#: exit status of errors in the user's input (same as argparse's usage errors)
EXIT_INPUT = 2
#: exit status of an unexpected exception (a bug of the library)
EXIT_INTERNAL = 1

#: widest default table for people, characters (``--columns`` may ask for more)
TABLE_WIDTH = 160

#: the conventions of every table (the epilog of ``--help``; docs/conventions.md has the rest)
CONVENTIONS = """\
table conventions (docs/conventions.md):
  i            position number, 1 .. n+1; position n+1 is position 1 one turn later
  phi_deg      input angle travelled from position 1 in the direction of rotation, deg:
               0, 360/n, ... 360 whatever the sense of rotation (over an input range A..B:
               from A towards B; in the start-up of --transient: 360 per cycle). Position 1
               is the declared start: the output's extreme position, --start DEG or A; the
               sense is the sign of the speed (--omega / --rpm, else the scheme's mean speed,
               else counter-clockwise). The '# start:' line (JSON: phi0_deg, direction) says
               both.
  L.theta      absolute angle of link L, CCW from +x, rad, in (-pi, pi]; for the input link
               it is the absolute input angle phi = phi0 + direction * phi_deg
  K.angle_deg  direction of a force, deg CCW from +x, in (-180, 180]
  q' q''       analogs dq/dphi, d2q/dphi2, per radian of the input angle (m/rad, rad/rad ...)
  units        SI: m, rad, N, N m, kg m^2, s (deg where the name ends in _deg); the table
               for people gives each column's unit in brackets under its name, JSON under
               "units"
  columns      the table for people shows the columns that matter within 160 characters and
               leaves out the frame points; CSV and JSON carry every column. --columns
               'B.*,3.theta' chooses columns by names and shell-style patterns (after i and
               phi_deg) in every format; --columns '*' gives them all."""


def _declared_dynamics(mech):
    """The scheme's dynamics inputs (parsed once, with the scheme), or None."""
    return section_of(mech, "dynamics")


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


#: the notes and warnings already said in this run (each is said once per run)
_SAID: set[str] = set()


def _note(kind: str, message: str) -> None:
    """One ``linkage: <kind>: ...`` line on stderr per line of ``message``; a note or warning
    already said in this run is not said again (errors always are)."""
    for line in str(message).splitlines() or [""]:
        text = f"{PROG}: {kind}: {_in_cli_terms(line)}\n"
        if kind != "error":
            if text in _SAID:
                continue
            _SAID.add(text)
        _write(sys.stderr, text)


#: advice of the Python API in messages of the library, and what it is on the command line
_IN_CLI_TERMS = (
    (re.compile(r" ?\(use on_failure='mask'[^)]*\)"),
     " (`linkage analyze SCHEME` shows every position, with the rows of these ones empty)"),
    (re.compile(r"; see Motion\.conditioning\)"), ")"),
    (re.compile(r"or pass delta="), "or give --delta"),
    (re.compile(r"pass mean_speed="), "give --omega or --rpm"),
    (re.compile(r"use the course method"), "use --method course"),
)


def _in_cli_terms(line: str) -> str:
    """A message of the library with its Python advice (``on_failure='mask'`` ...) said in the
    command line's terms."""
    for pattern, replacement in _IN_CLI_TERMS:
        line = pattern.sub(replacement, line)
    return line


def _error_lines(exc: BaseException) -> list[str]:
    if isinstance(exc, SchemeError):
        return [p for problem in exc.problems for p in str(problem).splitlines()]
    return str(exc).splitlines() or [type(exc).__name__]


# ----------------------------------------------------------------------------------------------
# linkage schemes
# ----------------------------------------------------------------------------------------------


class _HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter, except that a text with line breaks of its own (the epilog of
    conventions) is printed as written."""

    def _fill_text(self, text, width, indent):
        if "\n" in text:
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


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
    p.add_argument("--input-law", metavar="LINK:LAW", action="append", type=_input_law, default=[],
                   help="for a scheme with several input links: how the further input LINK turns with the "
                        "first input's angle phi, replacing the scheme's law; LAW is RATIO or RATIO:PHASE_DEG "
                        "(theta = RATIO * phi + PHASE), or the path of a CSV file of rows phi_deg,theta_deg "
                        "(docs/inputs.md); repeat it per link")


def _input_law(text: str):
    """``LINK:RATIO[:PHASE_DEG]`` or ``LINK:FILE.csv`` -> ``(link, InputLaw)``."""

    link, sep, law = text.partition(":")
    if not (link and sep and law):
        raise argparse.ArgumentTypeError(f"expected LINK:RATIO[:PHASE_DEG] or LINK:FILE.csv, got {text!r}")
    if law.lower().endswith(".csv"):
        table = _law_table(link, law)
        problems = table_problems(f"input law of link '{link}' ({law})", table)
        if problems:
            raise argparse.ArgumentTypeError("; ".join(problems))
        return link, InputLaw(table=table)
    ratio, _, phase = law.partition(":")
    values = [_real(ratio), _real(phase) if phase else 0.0]
    if values[0] == 0:
        raise argparse.ArgumentTypeError(f"input law of link '{link}': the ratio must be nonzero, got {ratio!r}")
    return link, InputLaw(values[0], math.radians(values[1]))


def _law_table(link: str, path: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The rows ``phi_deg,theta_deg`` of a CSV file (a header line allowed, ``#`` comments) in rad."""
    where = f"input law of link '{link}': {path}"
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise argparse.ArgumentTypeError(f"{where}: cannot read it ({exc})") from None
    rows = []
    for number, line in enumerate(lines, 1):
        cells = [c.strip() for c in line.split("#")[0].split(",")]
        if cells == [""]:
            continue
        try:
            if len(cells) != 2:
                raise ValueError
            rows.append([math.radians(float(c)) for c in cells])
        except ValueError:
            if rows or number > 1:    # only the first line may be a header
                raise argparse.ArgumentTypeError(f"{where}, line {number}: expected two numbers phi_deg,theta_deg, "
                                                 f"got {line.strip()!r}") from None
    return tuple(r[0] for r in rows), tuple(r[1] for r in rows)


def _load_scheme(args: argparse.Namespace):
    """The scheme named on the command line, with the input laws given by ``--input-law``."""
    mech = load(args.scheme)
    laws = dict(getattr(args, "input_law", []) or [])
    return mech.with_input_laws(**laws) if laws else mech


class _RangeAction(argparse.Action):
    """Parse ``--range A B`` into an :class:`InputRange` kept as the table's start (``args.start``):
    the range fixes position 1 at A, so it excludes ``--start``."""

    def __call__(self, parser, namespace, values, option_string=None):
        a, b = values
        if not 0 < abs(b - a) < 360:
            parser.error(f"argument --range: A and B must differ by more than 0 and less than 360 deg (a "
                         f"full turn needs no range: use --start), got {a:g} {b:g}")
        setattr(namespace, self.dest, InputRange(a, b))


def _range_end(text: str) -> float:
    try:
        deg = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an input angle in degrees, got {text!r}") from None
    if not (math.isfinite(deg) and abs(deg) <= MAX_ANGLE_DEG):
        raise argparse.ArgumentTypeError(f"expected a finite input angle in degrees with |x| <= "
                                         f"{MAX_ANGLE_DEG:g}, got {text!r}")
    return deg


def _add_positions_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--positions", "-n", metavar="N", type=_positions, default=None,
                   help="N equal steps per revolution (or over the input range); rows are positions "
                        "1..N+1 (default: the scheme's [dynamics] positions, else 12)")
    first = p.add_mutually_exclusive_group()
    first.add_argument("--start", metavar="extreme|DEG", type=_start, default=None,
                       help="position 1: 'extreme' = the extreme position of the scheme's output that "
                            "starts the cycle ('max' / 'min' pick one), or an input angle in degrees "
                            "(default: the scheme's [dynamics] start_deg, else 'extreme')")
    first.add_argument("--range", metavar=("A", "B"), nargs=2, type=_range_end, dest="start",
                       action=_RangeAction,
                       help="analyse the input angles from A to B (deg) in N steps instead of a turn, "
                            "for an input that does not turn fully (default: the scheme's range_deg, "
                            "if any)")


def _add_format_argument(p: argparse.ArgumentParser, formats: Sequence[str] = FORMATS) -> None:
    p.add_argument("--format", "-f", choices=formats, default="table",
                   help="aligned text for people (default; the columns that matter), CSV at full "
                        "precision, or JSON (CSV and JSON: every column)")


def _add_columns_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--columns", "-c", metavar="LIST", default=None,
                   help="the columns to give, after i and phi_deg, in every format: names and "
                        "shell-style patterns separated by commas, e.g. 'B.*,3.theta'; '*' gives "
                        "them all (default: the table for people shows the columns that matter, "
                        "CSV and JSON every column)")


def _leading(columns) -> tuple[str, str]:
    """The columns that lead a table: ``i`` and its position column (``phi_deg``, or ``s`` for a
    slide input)."""
    return ("i", "s") if "s" in columns else ("i", "phi_deg")


def _emit(columns: dict, args, meta: dict, default_view: Callable[[dict], list[str]] | None = None,
          always: Sequence[str] | None = None) -> None:
    """Print a table in ``args.format``: the columns ``--columns`` asks for; without it, every
    column in CSV / JSON and ``default_view(columns)`` in the table for people (with one line
    saying how to see the others)."""
    units = units_of(columns)
    always = _leading(columns) if always is None else always
    if args.columns is not None:
        try:
            columns = select_columns(columns, args.columns, always=always)
        except InputError as exc:
            raise InputError(f"--columns {args.columns!r}: {exc}") from None
    elif args.format == "table" and default_view is not None:
        shown = default_view(columns)
        if len(shown) < len(columns):
            meta = {**meta, "columns": f"{len(shown)} of {len(columns)} shown; all of them: --columns '*' "
                                       "(or --format csv / json)"}
        columns = {name: columns[name] for name in shown}
    if args.format == "json":
        meta = {**meta, "conventions": JSON_CONVENTIONS}
    _out(format_columns(columns, args.format, meta=meta, units=units))


def _constant(values) -> bool:
    """All values equal to within 1e-12 of their magnitude (or all missing)."""
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    return not len(finite) or float(np.ptp(finite)) <= 1e-12 * float(np.max(np.abs(finite)))


def _same(a, b) -> bool:
    """Two columns equal to within 1e-12 of their magnitude (missing values in the same rows)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape or not np.array_equal(np.isfinite(a), np.isfinite(b)):
        return False
    ok = np.isfinite(a)
    scale = max(float(np.max(np.abs(a[ok]), initial=0.0)), float(np.max(np.abs(b[ok]), initial=0.0)))
    return bool(np.all(np.abs(a[ok] - b[ok]) <= 1e-12 * scale))


def _fit(columns: dict, lead: Sequence[str], groups: Sequence[Sequence[str]], *,
         skip_repeats: bool = False) -> list[str]:
    """``lead`` and then the ``groups`` of column names, in order of priority, as long as the
    table for people stays within :data:`TABLE_WIDTH` characters (names missing from ``columns``
    are skipped; with ``skip_repeats``, so is a group whose columns are all constant, such as the
    angle of a slider on a fixed guide, or repeat columns already shown, such as the slide of a
    slider whose guide runs along x; a group that would not fit ends the selection)."""
    shown = [name for name in lead if name in columns]
    units = units_of(columns)
    for group in groups:
        extra = [name for name in group if name in columns and name not in shown]
        if not extra or skip_repeats and all(
                _constant(columns[name]) or any(_same(columns[name], columns[other]) for other in shown)
                for name in extra):
            continue
        trial = shown + extra
        if table_width({name: columns[name] for name in trial}, units) > TABLE_WIDTH:
            break
        shown = trial
    return shown


def _add_analyze(sub) -> None:
    p = sub.add_parser(
        "analyze", help="kinematics table: positions, velocity and acceleration analogs",
        formatter_class=_HelpFormatter, epilog=CONVENTIONS,
        description="Positions and first / second transfer functions (analogs, d/dphi) of every "
                    "named point, moving link angle and prismatic slide, at N equal steps of the "
                    "input angle phi (docs/conventions.md). Columns: i, phi_deg; P.x P.y P.x' P.y' "
                    "P.x'' P.y''; L.theta L.theta' L.theta''; K.s K.s' K.s'' (m, rad). The table "
                    "for people shows the absolute input angle, the scheme's output and the "
                    "moving links and slides with their analogs, as many as fit.")
    _add_scheme_argument(p)
    _add_positions_arguments(p)
    _add_columns_argument(p)
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_analyze)


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
        return _fit(columns, _leading(columns), groups, skip_repeats=True)
    return view


def _sense_in_words(direction: int) -> str:
    return "counter-clockwise" if direction > 0 else "clockwise"


def _start_line(mech, phi: np.ndarray, start, n: int, direction: int | None = None) -> str:
    """The ``# start:`` line of a table for people: position 1 and how phi_deg counts (along the
    table: in the direction of rotation over a turn, from A towards B over an input range)."""
    if not mech.coordinate.is_angle:
        s0, s1 = (round(float(v), 12) + 0.0 for v in (phi[0], phi[-1]))
        return (f"s0 = {s0:.10g} m (start of the stroke); s runs to {s1:.10g} m, {n} steps over the stroke "
                f"(input: the slide of pair '{mech.input_pair(mech.inputs[0])}')")
    sense = direction if direction is not None else (1 if len(phi) < 2 or phi[-1] >= phi[0] else -1)
    phi0 = round(float(np.degrees(phi[0])), 10) + 0.0  # no round-off noise such as 5e-14 deg for 0
    if start == "range":
        end = round(float(np.degrees(phi[-1])), 10) + 0.0
        sense = 1 if end >= phi0 else -1
        return (f"phi0 = {phi0:.10g} deg (start of the input range); phi_deg counts from it "
                f"{_sense_in_words(sense)} to {end:.10g} deg, {n} steps over the range")
    where = ""
    if isinstance(start, str) and mech.output is not None:
        which = mech.output.start if start == "extreme" else start
        where = f" ({which} of {mech.output.quantity})"
    return (f"phi0 = {phi0:.10g} deg{where}; phi_deg counts from it {_sense_in_words(sense)}, "
            f"{n} steps per revolution")


def _cmd_analyze(args: argparse.Namespace) -> int:
    mech = _load_scheme(args)
    results = kinematics_results(mech, args.positions, args.start)
    _say(results)
    meta = results.meta
    if args.format == "table":
        phi = results.motion.phi
        meta = {"scheme": mech.name, "formula": meta["formula"],
                "start": _start_line(mech, phi, meta["start"], meta["positions"], declared_rotation(mech))}
    _emit(results.columns, args, meta, _analyze_view(mech))
    return 0


def _say(results) -> None:
    """The notes and warnings of a table on stderr."""
    for line in results.notes:
        _note("note", line)
    for line in results.warnings:
        _note("warning", line)


# ----------------------------------------------------------------------------------------------
# linkage forces
# ----------------------------------------------------------------------------------------------


def _add_speed_arguments(p: argparse.ArgumentParser, what: str) -> None:
    speed = p.add_mutually_exclusive_group()
    speed.add_argument("--omega", metavar="RAD_S", type=_real,
                       help=f"{what}, rad/s, signed (negative: clockwise); for a slide input its "
                            "speed, m/s")
    speed.add_argument("--rpm", metavar="RPM", type=_real, help=f"{what}, rpm, signed")


def _speed(args, mech=None) -> float | None:
    """The input speed the options give (rad/s, or m/s for a slide input of ``mech``); --rpm
    turns a crank, so a slide input refuses it."""
    if args.rpm is not None:
        if mech is not None and not mech.coordinate.is_angle:
            raise InputError(f"--rpm {args.rpm:g}: scheme '{mech.name}' is driven by a slide (input "
                             f"'{mech.inputs[0]}'), whose speed is in m/s: give --omega M_S (the slide's speed)")
        return args.rpm * RPM
    return args.omega


def _add_forces(sub) -> None:
    p = sub.add_parser(
        "forces", help="kinetostatics: pair reactions and the balancing moment",
        formatter_class=_HelpFormatter, epilog=CONVENTIONS,
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
    _add_scheme_argument(p)
    _add_positions_arguments(p)
    _add_speed_arguments(p, "input angular velocity (default: the scheme's mean speed, else "
                            "none: a static analysis)")
    p.add_argument("--eps", metavar="RAD_S2", type=_real, default=0.0,
                   help="input angular acceleration, rad/s^2 (default 0); for a slide input, m/s^2")
    _add_columns_argument(p)
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_forces)


def _forces_view(columns: dict) -> list[str]:
    """The default columns of ``linkage forces`` for people: the balancing moment, then the
    magnitude of every reaction, then their directions, as many as fit, in table order."""
    pairs = [name[:-2] for name in columns if name.endswith(".R")]
    moments = [name for name in columns if name.startswith("balancing_")]
    groups = [moments] + [[f"{k}.R"] for k in pairs] + [[f"{k}.angle_deg"] for k in pairs]
    shown = set(_fit(columns, _leading(columns), groups))
    return [name for name in columns if name in shown]


def _cmd_forces(args: argparse.Namespace) -> int:
    mech = _load_scheme(args)
    results = forces_results(mech, args.positions, args.start, _speed(args, mech), args.eps)
    _say(results)
    meta = results.meta
    if args.format == "table":
        omega, phi = meta["omega"], results.motion.phi
        direction = declared_rotation(mech) if not omega else int(np.sign(omega))
        unit = mech.coordinate.unit
        speed = "none (static analysis)" if omega is None else f"{omega:.6g} {unit}/s"
        meta = {"scheme": mech.name, "start": _start_line(mech, phi, meta["start"], meta["positions"], direction),
                "omega": speed, "eps": f"{args.eps:.6g} {unit}/s^2", "convention": meta["convention"],
                "virtual_power_residual_max": meta["virtual_power_residual_max"]}
    _emit(results.columns, args, meta, _forces_view)
    return 0


# ----------------------------------------------------------------------------------------------
# linkage dynamics
# ----------------------------------------------------------------------------------------------


def _add_dynamics(sub) -> None:
    p = sub.add_parser(
        "dynamics", help="machine dynamics: flywheel, law of motion, reactions under real motion",
        formatter_class=_HelpFormatter, epilog=CONVENTIONS,
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
    _add_scheme_argument(p)
    p.add_argument("--positions", "-n", metavar="N", type=_positions, default=None,
                   help="N equal steps per revolution (default: the scheme's, else 12)")
    p.add_argument("--delta", metavar="D", type=_real, default=None,
                   help="coefficient of speed fluctuation (default: the scheme's)")
    _add_speed_arguments(p, "mean speed of the input link (default: the scheme's)")
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
    stroke.add_argument("--force", metavar="N", type=_real, default=None,
                        help="the actuator's force along +s, N (default 0: the declared loads alone)")
    stroke.add_argument("--initial-speed", metavar="M_S", type=_real, default=None,
                        help="|ds/dt| at the start of the stroke, m/s (default 0: from rest)")
    _add_columns_argument(p)
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_dynamics)


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
    _emit(columns, args, meta, None)
    return 0


#: units of the scalar results of ``linkage dynamics`` (the ``# key: value`` lines of the table)
_SUMMARY_UNITS = {
    "driving_moment": "N m", "required_constant_inertia": "kg m^2", "flywheel_inertia": "kg m^2",
    "mean_speed_actual": "rad/s", "constant_inertia": "kg m^2",
    "exact_required_constant_inertia": "kg m^2", "exact_flywheel_inertia": "kg m^2",
    "transient_time": "s", "settling_time": "s", "initial_speed": "rad/s",
}


def _dynamics_view(columns: dict) -> list[str]:
    """The default columns of ``linkage dynamics`` for people: the law of motion, the balancing
    moment, then the reduced characteristics, as many as fit, in table order."""
    groups = [["omega"], ["eps"], ["balancing_moment"], ["reduced_moment_resistance"], ["reduced_inertia"],
              ["reduced_moment_driving"], ["reduced_inertia_derivative"]]
    shown = set(_fit(columns, ("i", "phi_deg", "t"), groups))
    return [name for name in columns if name in shown]


def _cmd_dynamics(args: argparse.Namespace) -> int:

    mech = _load_scheme(args)
    if not mech.coordinate.is_angle:
        return _cmd_stroke(args, mech)
    if args.force is not None or args.initial_speed is not None:
        given = "--force" if args.force is not None else "--initial-speed"
        raise InputError(f"{given}: scheme '{mech.name}' is driven by a crank (input '{mech.inputs[0]}'); "
                         "--force and --initial-speed are for a slide input")
    if args.transient and args.method != "ode":
        raise InputError(f"--transient: the start-up is a solution of the equation of motion with the "
                         f"motor: give --method ode with it (got --method {args.method})")
    declared = _declared_dynamics(mech)
    spec = None
    if args.method == "ode":
        with _options_named(args):
            spec = _override(mech, None, args.delta, _speed(args), args.positions)
        if args.transient and spec.initial_speed is None:
            raise InputError(f"--transient: scheme '{mech.name}' declares no speed to start from: give "
                             "initial_rpm (or initial_speed, rad/s) in its [dynamics] section")
        first = "sizing the flywheel (exact method), then " if spec.delta is not None else ""
        then = " and integrating the start-up transient" if spec.initial_speed is not None else ""
        _note("note", f"{first}shooting for the motor-driven steady state{then}; this takes a few seconds")
    with _options_named(args):
        results = dynamics_results(mech, args.method, positions=args.positions, delta=args.delta,
                                   mean_speed=_speed(args))
    report, summary = results.report, dict(results.summary)
    for note in report.notes:
        _note("note", note)
    if spec is not None:
        _ode_notes(mech, spec, report)
    law = report.law
    direction = law.reduced.rotation
    n = len(law.phi) - 1
    if args.transient:
        transient = simulate(mech, spec, constant_inertia=law.constant_inertia)
        columns = transient.columns()
        summary.update(initial_speed=spec.initial_speed)
        start = (f"t = 0 at phi0 = {round(float(np.degrees(law.phi[0])), 10) + 0.0:.10g} deg, "
                 f"|omega| = {spec.initial_speed:.6g} rad/s; phi_deg counts from it "
                 f"{_sense_in_words(direction)}, 360 per cycle, {spec.cycles} cycles")
        always = ("t", "phi_deg")
    else:
        columns = results.columns
        start = _start_line(mech, law.phi, declared.start if declared is not None else "extreme", n, direction)
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
    _emit(columns, args, summary, _dynamics_view, always=always)
    return 0


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
        _note("note", f"scheme '{mech.name}' declares no [dynamics.motor]: --method ode drives the crank "
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
        _note("note", f"the motor's steady mean speed {actual:.4g} rad/s differs from the declared mean "
                      f"speed {declared:.4g} rad/s by {100 * miss:.3g} %, more than delta = {spec.delta:g}: "
                      "the flywheel was sized for the declared speed; check the motor's data in "
                      "[dynamics.motor] (ratio, synchronous_rpm, rated_rpm ...) or the mean speed")


# ----------------------------------------------------------------------------------------------
# linkage report, linkage variants
# ----------------------------------------------------------------------------------------------


def _progress(what: str):
    """A progress bar on stderr (tqdm; shown only when stderr is a terminal) for a stream of
    ``total`` steps: ``bar(iterable, total)``."""
    from tqdm import tqdm

    def bar(iterable, total=None):
        return tqdm(iterable, total=total, desc=f"{PROG}: {what}", unit="step" if total else "draw",
                    file=sys.stderr, disable=None, leave=False)
    return bar


def _add_report(sub) -> None:
    p = sub.add_parser(
        "report", help="a complete analysis folder: tables, pictures, animation, an HTML page",
        description="Write a complete analysis of a scheme into a folder: the CSV and JSON tables of "
                    "'analyze', 'forces' and (with a [dynamics] section) 'dynamics'; PNG and SVG "
                    "pictures (the mechanism to scale, kinematic diagrams, balancing moment, "
                    "hodographs of reactions, reduced moments and work, energy-inertia diagram, "
                    "flywheel, omega and eps two ways, start-up with the motor); animation.gif, one "
                    "revolution; and index.html, one page with the data, the structural formula, the "
                    "results and every picture. Pictures the scheme's data does not allow are left "
                    "out with a note. Needs the 'report' extra: pip install \"linkage[report]\".")
    _add_scheme_argument(p)
    p.add_argument("--out", "-o", metavar="DIR", required=True, help="the folder to write (created)")
    p.set_defaults(handler=_cmd_report)


def _cmd_report(args: argparse.Namespace) -> int:

    require_report_extra()
    mech = _load_scheme(args)
    report = write_report(mech, args.out, progress=_progress("report"))
    for line in report.notes:
        _note("note", line)
    _out(f"{Path(args.out) / 'index.html'}: {len(report.pictures)} pictures, {len(report.files)} files")
    return 0


def _whole(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: a whole number in [low, high]."""
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if not low <= n <= high:
            raise argparse.ArgumentTypeError(f"expected a whole number in [{low}, {high}], got {n}")
        return n
    return parse


def _add_variants(sub) -> None:
    p = sub.add_parser(
        "variants", help="course assignments: N feasible variants of a template, each with its sheet and key",
        description="Draw N distinct feasible variants of a template (docs/templates.md; shipped: "
                    "press_slider_crank, shaper_two_dyad) reproducibly from a seed, or take a "
                    "teacher's table of given variants (--table), and write one folder per variant: "
                    "scheme.toml, sheet.pdf (the drawing to scale, the data, what to compute), "
                    "key.json (the answer key: the fields of 'linkage dynamics scheme.toml --format "
                    "json' with the same values, plus the parameters and the checks) and the CSV "
                    "tables; plus index.csv, index.pdf and selection.json (how many draws each "
                    "feasibility rule rejected). The same seed gives byte-identical files. Needs the "
                    "'report' extra: pip install \"linkage[report]\".")
    p.add_argument("template", metavar="TEMPLATE",
                   help="a shipped template name or the path of a template file")
    p.add_argument("--count", "-n", metavar="N", type=_whole(1, 100_000), default=None,
                   help="variants to make (default: 10; with --table: every row)")
    p.add_argument("--seed", "-s", metavar="S", type=_whole(0, 2**63 - 1), default=None,
                   help="seed of the draws (required without --table)")
    p.add_argument("--table", metavar="CSV", default=None,
                   help="a CSV of given variants, one row per variant (columns: the free parameters, "
                        "optionally 'variant')")
    p.add_argument("--out", "-o", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--workers", "-j", metavar="K", type=_whole(1, 1024), default=1,
                   help="build the variants in K worker processes (default 1)")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="build the variants on a Dask distributed cluster at ADDRESS (tcp://host:8786); "
                        "needs the 'dask' extra: pip install \"linkage[dask]\"")
    p.add_argument("--max-draws", metavar="D", type=_whole(1, 10_000_000), default=None,
                   help="stop drawing after D draws (default: max(1000, 50 N))")
    p.set_defaults(handler=_cmd_variants)


def _cmd_variants(args: argparse.Namespace) -> int:

    require_report_extra("linkage variants")
    if args.table is None and args.seed is None:
        raise InputError("give --seed S for the draws (or --table CSV of given variants)")
    if args.table is not None and not Path(args.table).is_file():
        raise InputError(f"--table {args.table}: no such file")
    template = load_template(args.template)
    count = args.count if args.count is not None else (100_000 if args.table is not None else 10)
    selection = select_variants(template, count, args.seed, given=args.table, max_draws=args.max_draws,
                                progress=_progress("drawing feasible variants"))
    for line in selection.lines():
        _note("note", line)
    if not selection.variants:
        raise InputError(f"template '{template.name}': no feasible variant (see the notes above)")
    folders = write_variants(selection, args.out, workers=args.workers, scheduler=args.scheduler,
                             progress=_progress("building variants"))
    _out(f"{Path(args.out) / 'index.csv'}: {len(folders)} variants")
    return 0 if len(selection.variants) == count or args.table is not None else EXIT_INPUT


# ----------------------------------------------------------------------------------------------
# linkage enumerate
# ----------------------------------------------------------------------------------------------


def _add_enumerate(sub) -> None:

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
    _add_scheme_argument(p)
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="write the schemes and the tables into DIR (created)")
    p.add_argument("--omega", metavar="RAD_S", type=_real, default=DEFAULT_OMEGA,
                   help=f"input speed of the balancing moment, rad/s, signed (default {DEFAULT_OMEGA:g})")
    p.add_argument("--newton", action="store_true",
                   help="also search a full-turn geometry for the combinations with a group solved by Newton's "
                        "method (slow: about 1-2 s per trial, minutes for a six-bar); without it they are listed "
                        "as 'not searched'")
    p.add_argument("--rejected", action="store_true",
                   help="list the rejected assignments and why, instead of the table")
    _add_format_argument(p)
    p.set_defaults(handler=_cmd_enumerate)


def _cmd_enumerate(args: argparse.Namespace) -> int:

    def progress(iterable, total=None):
        try:
            from tqdm import tqdm
        except ImportError:  # the bar is a nicety of the report extra
            return iterable
        return tqdm(iterable, total=total, desc=f"{PROG}: combinations", unit="combination", file=sys.stderr,
                    disable=None, leave=False, delay=1.0)

    if args.omega == 0.0:
        raise InputError("--omega 0: the balancing moment needs a nonzero speed, rad/s")
    found = enumerate_chain(_load_scheme(args), omega=args.omega, newton=args.newton, progress=progress)
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
        _note("note", f"scheme '{found.source}': no {'rejected' if args.rejected else 'solvable'} assignment")
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
        _out(text or f"# scheme: {found.source}")
    else:
        _out(format_columns(columns, args.format, meta=meta if args.format == "json" else None, units=units)
             if len(columns["id"]) else ",".join(columns))
    if args.out is not None:
        _note("note", f"{Path(args.out)}: {running} schemes, combinations.csv, rejected.csv")
    return 0


# ----------------------------------------------------------------------------------------------
# linkage plans
# ----------------------------------------------------------------------------------------------


def _add_plans(sub) -> None:
    p = sub.add_parser(
        "plans", help="the graphical method: plans of velocities and accelerations, force polygons, the lever",
        formatter_class=_HelpFormatter, epilog=CONVENTIONS,
        description="The plans of velocities and accelerations (vectors from a pole, group by group), the force "
                    "polygon of every Assur group and input link, and Zhukovsky's lever (the velocity plan turned "
                    "by 90 deg with the forces at their image points) at one table position, from the exact "
                    "kinematics and kinetostatics (docs/plans.md). JSON (default, on stdout): phi_deg (deg), "
                    "velocity and acceleration (point -> [x, y], m/s and m/s^2), angular_velocity (rad/s), "
                    "angular_acceleration (rad/s^2), velocity_plan, acceleration_plan, force_polygons (N, N m), "
                    "lever, lever_balancing_moment and balancing_moment (N m). svg / png: the drawings to scale "
                    "(plans, force polygons, lever, and a sheet with the mechanism), written into --out.")
    _add_scheme_argument(p)
    p.add_argument("--position", "-i", metavar="I", type=_whole(1, MAX_POSITIONS + 1), required=True,
                   help="the position number of the table, 1 .. N+1, as in 'linkage analyze' and 'linkage forces' "
                        "(position 1: the scheme's start, by default the output's extreme position)")
    _add_positions_arguments(p)
    _add_speed_arguments(p, "input angular velocity (default: the scheme's mean speed, else 1 rad/s with a note)")
    p.add_argument("--eps", metavar="RAD_S2", type=_real, default=0.0,
                   help="input angular acceleration, rad/s^2 (default 0)")
    p.add_argument("--format", "-f", choices=("json", "svg", "png"), default="json",
                   help="JSON numbers on stdout (default), or the drawings as SVG or PNG files")
    p.add_argument("--out", "-o", metavar="DIR", default=None,
                   help="the folder to write into (created; default for drawings: the current folder); with "
                        "json the document is written to DIR/SCHEME_position_I.json instead of stdout")
    for option, what in (("--mu-v", "velocity plan, (m/s)/mm"), ("--mu-a", "acceleration plan, (m/s^2)/mm"),
                         ("--mu-f", "force polygons, N/mm")):
        p.add_argument(option, metavar="MU", type=_real, default=None,
                       help=f"scale of the {what} (default: chosen so that the largest vector is about 80 mm)")
    p.set_defaults(handler=_cmd_plans)


def _cmd_plans(args: argparse.Namespace) -> int:
    import json


    mech = _load_scheme(args)
    require_crank_input(mech)
    for option, value in (("--mu-v", args.mu_v), ("--mu-a", args.mu_a), ("--mu-f", args.mu_f)):
        if value is not None and value <= 0:
            raise InputError(f"{option} {value:g}: a scale must be positive (units per mm)")
    omega, spec = _speed(args), _declared_dynamics(mech)
    if omega is None and spec is not None:
        omega = spec.mean_speed
    notes = []
    if omega is None:
        omega = 1.0
        notes.append(f"scheme '{mech.name}' declares no speed and none was given: omega = 1 rad/s (the plans of "
                     "the analogs, in m/s per rad/s); give --omega or --rpm for the real speed")
        _note("note", notes[-1])
    if omega == 0:
        raise InputError("--omega 0: the plans need a moving input; give a nonzero speed, rad/s")
    results = forces_results(mech, args.positions, args.start, omega, args.eps)
    _say(results)
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
        _out("\n".join(str(path) for path in written))
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
        _out(text)
    else:
        path = Path(args.out) / f"{stem}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text + "\n", encoding="utf-8")
        _out(str(path))
    return 0


# ----------------------------------------------------------------------------------------------
# the parser and main
# ----------------------------------------------------------------------------------------------

#: functions that register one subcommand each, in the order ``--help`` lists them
COMMANDS: list[Callable] = [_add_schemes, _add_analyze, _add_forces, _add_dynamics, _add_report, _add_variants,
                            _add_enumerate, _add_plans]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Planar linkage analysis: Assur groups, exact kinematics, "
                               "kinetostatics and machine dynamics.",
        formatter_class=_HelpFormatter, epilog=CONVENTIONS)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in COMMANDS:
        register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    _SAID.clear()  # each run says its notes once
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
        _note("warning", NUMERICAL_WARNING)
