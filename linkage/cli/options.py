"""What the commands of :mod:`linkage.cli` share.

- the program's name, its exit statuses (:data:`EXIT_INPUT`, :data:`EXIT_INTERNAL`), the widest
  default table (:data:`TABLE_WIDTH`) and the table conventions of ``--help`` (:data:`CONVENTIONS`);
- argument types: :func:`positions`, :func:`real`, :func:`whole`, start angles, input ranges
  (``--range A B``) and input laws (``--input-law LINK:LAW``);
- the functions that add the common arguments: :func:`add_scheme_argument`,
  :func:`add_positions_arguments`, :func:`add_speed_arguments`, :func:`add_columns_argument`,
  :func:`add_format_argument`; :class:`HelpFormatter`, which prints the conventions as written;
- reading them back: :func:`load_scheme`, :func:`input_speed`, :func:`declared_dynamics`;
- the output: :func:`out` (stdout), :func:`note` (``linkage: note|warning|error: ...`` on stderr,
  each note once per run), :func:`error_lines`, :func:`say` (a table's notes and warnings),
  :func:`emit` (a table in the chosen format and columns), :func:`fit` and :func:`leading` (the
  default columns of a table for people), :func:`start_line` (its ``# start:`` line) and
  :func:`progress` (a progress bar on stderr).
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..dynamics.motors import RPM
from ..errors import InputError, SchemeError
from ..model.input_laws import InputLaw, table_problems
from ..model.numbers import MAX_ANGLE_DEG, MAX_MAGNITUDE, MAX_POSITIONS
from ..model.plausibility import warn_fast_speed
from ..model.scheme import load, section_of
from ..report import FORMATS, format_columns
from ..report.results import JSON_CONVENTIONS, InputRange
from ..report.tables import select_columns, table_width, units_of

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
  q' q''       analogs d/dpsi, d2/dpsi2, psi = phi_deg in rad (m/rad, rad/rad ...): q' is the
               slope of q over phi_deg for either sense (the Python API's Motion: d/dphi)
  units        SI: m, rad, N, N m, kg m^2, s (deg where the name ends in _deg); the table
               for people gives each column's unit in brackets under its name, JSON under
               "units"
  columns      the table for people shows the columns that matter within 160 characters and
               leaves out the frame points; CSV and JSON carry every column. --columns
               'B.*,3.theta' chooses columns by names and shell-style patterns (after i and
               phi_deg) in every format; --columns '*' gives them all."""


def declared_dynamics(mech):
    """The scheme's dynamics inputs (parsed once, with the scheme), or None."""
    return section_of(mech, "dynamics")


def _write(stream, text: str) -> None:
    """Write ``text``; characters the stream cannot encode (e.g. '→' on a cp1252 pipe) are
    replaced instead of failing."""
    try:
        stream.write(text)
    except UnicodeEncodeError:
        enc = getattr(stream, "encoding", None) or "ascii"
        stream.write(text.encode(enc, errors="replace").decode(enc))


def out(text: str) -> None:
    _write(sys.stdout, text if text.endswith("\n") else text + "\n")


#: the notes and warnings already said in this run (each is said once per run)
SAID: set[str] = set()


def note(kind: str, message: str) -> None:
    """One ``linkage: <kind>: ...`` line on stderr per line of ``message``; a note or warning
    already said in this run is not said again (errors always are)."""
    for line in str(message).splitlines() or [""]:
        text = f"{PROG}: {kind}: {_in_cli_terms(line)}\n"
        if kind != "error":
            if text in SAID:
                continue
            SAID.add(text)
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


def error_lines(exc: BaseException) -> list[str]:
    if isinstance(exc, SchemeError):
        return [p for problem in exc.problems for p in str(problem).splitlines()]
    return str(exc).splitlines() or [type(exc).__name__]


class HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter, except that a text with line breaks of its own (the epilog of
    conventions) is printed as written."""

    def _fill_text(self, text, width, indent):
        if "\n" in text:
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


def positions(text: str) -> int:
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


def real(text: str) -> float:
    """A finite number within the declared range of every number (|x| <= 1e50)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and abs(value) <= MAX_MAGNITUDE):
        raise argparse.ArgumentTypeError(f"expected a finite number with |x| <= {MAX_MAGNITUDE:g}, got {text!r}")
    return value


def add_scheme_argument(p: argparse.ArgumentParser) -> None:
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
    values = [real(ratio), real(phase) if phase else 0.0]
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


def load_scheme(args: argparse.Namespace):
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


def add_positions_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--positions", "-n", metavar="N", type=positions, default=None,
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


def add_format_argument(p: argparse.ArgumentParser, formats: Sequence[str] = FORMATS) -> None:
    p.add_argument("--format", "-f", choices=formats, default="table",
                   help="aligned text for people (default; the columns that matter), CSV at full "
                        "precision, or JSON (CSV and JSON: every column)")


def add_columns_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--columns", "-c", metavar="LIST", default=None,
                   help="the columns to give, after i and phi_deg, in every format: names and "
                        "shell-style patterns separated by commas, e.g. 'B.*,3.theta'; '*' gives "
                        "them all (default: the table for people shows the columns that matter, "
                        "CSV and JSON every column)")


def leading(columns) -> tuple[str, str]:
    """The columns that lead a table: ``i`` and its position column (``phi_deg``, or ``s`` for a
    slide input)."""
    return ("i", "s") if "s" in columns else ("i", "phi_deg")


def emit(columns: dict, args, meta: dict, default_view: Callable[[dict], list[str]] | None = None,
         always: Sequence[str] | None = None) -> None:
    """Print a table in ``args.format``: the columns ``--columns`` asks for; without it, every
    column in CSV / JSON and ``default_view(columns)`` in the table for people (with one line
    saying how to see the others)."""
    units = units_of(columns)
    always = leading(columns) if always is None else always
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
    out(format_columns(columns, args.format, meta=meta, units=units))


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


def fit(columns: dict, lead: Sequence[str], groups: Sequence[Sequence[str]], *,
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


def sense_in_words(direction: int) -> str:
    return "counter-clockwise" if direction > 0 else "clockwise"


def start_line(mech, phi: np.ndarray, start, n: int, direction: int | None = None) -> str:
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
                f"{sense_in_words(sense)} to {end:.10g} deg, {n} steps over the range")
    where = ""
    if isinstance(start, str) and mech.output is not None:
        which = mech.output.start if start == "extreme" else start
        where = f" ({which} of {mech.output.quantity})"
    return (f"phi0 = {phi0:.10g} deg{where}; phi_deg counts from it {sense_in_words(sense)}, "
            f"{n} steps per revolution")


def say(results) -> None:
    """The notes and warnings of a table on stderr."""
    for line in results.notes:
        note("note", line)
    for line in results.warnings:
        note("warning", line)


def add_speed_arguments(p: argparse.ArgumentParser, what: str) -> None:
    speed = p.add_mutually_exclusive_group()
    speed.add_argument("--omega", metavar="RAD_S", type=real,
                       help=f"{what}, rad/s, signed (negative: clockwise); for a slide input its "
                            "speed, m/s")
    speed.add_argument("--rpm", metavar="RPM", type=real, help=f"{what}, rpm, signed")


def input_speed(args, mech=None) -> float | None:
    """The input speed the options give (rad/s, or m/s for a slide input of ``mech``); --rpm
    turns a crank, so a slide input refuses it."""
    if args.rpm is not None:
        if mech is not None and not mech.coordinate.is_angle:
            raise InputError(f"--rpm {args.rpm:g}: scheme '{mech.name}' is driven by a slide (input "
                             f"'{mech.inputs[0]}'), whose speed is in m/s: give --omega M_S (the slide's speed)")
        warn_fast_speed(f"--rpm {args.rpm:g}", args.rpm * RPM, mech)
        return args.rpm * RPM
    if args.omega is not None:
        warn_fast_speed(f"--omega {args.omega:g}", args.omega, mech)
    return args.omega


def whole(low: int, high: int) -> Callable[[str], int]:
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


def progress(what: str):
    """A progress bar on stderr (tqdm; shown only when stderr is a terminal) for a stream of
    ``total`` steps: ``bar(iterable, total)``."""
    from tqdm import tqdm

    def bar(iterable, total=None):
        return tqdm(iterable, total=total, desc=f"{PROG}: {what}", unit="step" if total else "draw",
                    file=sys.stderr, disable=None, leave=False)
    return bar
