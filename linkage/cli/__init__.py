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
    linkage sheets SCHEME --out DIR [--position I] [--format pdf,dxf,svg] [--paper A1|A2|A3]
                                                      the course project's drawing sheets to scale
    linkage variants TEMPLATE ...                     course assignments from a template
    linkage grade FOLDER ANSWERS [--out DIR]          grade a class's answers against the keys
    linkage enumerate SCHEME [--out DIR]              every R/P assignment of the chain's pairs
    linkage plans SCHEME --position I [--omega W | --rpm R] [--eps E] [--format json|svg|png]
                         [--out DIR]                 plans, force polygons, Zhukovsky's lever
    linkage synthesize --links N [--out DIR] [--with-geometry] ...   every 1-DOF mechanism of N links

Every scheme argument takes ``--input-law LINK:LAW`` for the further inputs of a mechanism with
several (docs/inputs.md).

The package holds one module per command (:mod:`.schemes`, :mod:`.analyze`, :mod:`.forces`,
:mod:`.dynamics`, :mod:`.report`, :mod:`.sheets`, :mod:`.variants`, :mod:`.grade`, :mod:`.enumeration`, :mod:`.plans`), each with
an ``add(subparsers)`` function that registers its parser and sets ``handler`` to its
``run(args) -> int``, and :mod:`.options` with what the commands share: the argument types and
the functions that add the common arguments, the help formatter, the table conventions and the
output helpers. Add a new command by writing such a module and listing its ``add`` in
:data:`COMMANDS`; this module holds only :func:`build_parser` and :func:`main`. Tables go to
stdout through :func:`linkage.report.format_columns`: CSV and JSON carry every column, the table
for people a default selection at most :data:`~linkage.cli.options.TABLE_WIDTH` characters wide
(frame points left out), and ``--columns`` chooses the columns in every format
(:data:`~linkage.cli.options.CONVENTIONS` says what they mean). Defaults follow the scheme:
positions, start, speed and loads declared in it. Notes, warnings and errors go to stderr, each
note once per run. Errors of the input (:class:`linkage.LinkageError`, the family of every error
the library raises on purpose, and argparse's) print one line per problem and exit with status
:data:`EXIT_INPUT` (2), without a traceback, as does a file or folder that cannot be read or
written (``OSError``); warnings are printed as ``linkage: warning: ...``
lines (never as Python's warning text); any other exception (a bug, a bare ``ValueError`` of
numpy included) prints one ``internal error`` line and exits with status :data:`EXIT_INTERNAL` (1).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from typing import Callable, Sequence

from ..errors import LinkageError
from ..report.results import NUMERICAL_WARNING
from ..version import __version__
from . import analyze, dynamics, enumeration, forces, grade, plans, report, schemes, sheets, synthesize, variants
from .options import CONVENTIONS, EXIT_INPUT, EXIT_INTERNAL, PROG, SAID, HelpFormatter, error_lines, note

__all__ = ["main", "build_parser", "COMMANDS", "EXIT_INPUT", "EXIT_INTERNAL"]


#: functions that register one subcommand each, in the order ``--help`` lists them
COMMANDS: list[Callable] = [schemes.add, analyze.add, forces.add, dynamics.add, report.add, sheets.add, variants.add,
                            grade.add,
                            enumeration.add, plans.add, synthesize.add]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description="Planar linkage analysis: Assur groups, exact kinematics, "
                               "kinetostatics and machine dynamics.",
        formatter_class=HelpFormatter, epilog=CONVENTIONS)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in COMMANDS:
        register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line with ``argv`` (default ``sys.argv[1:]``); return the exit status."""
    parser = build_parser()
    SAID.clear()  # each run says its notes once
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors (status 2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else EXIT_INPUT)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return args.handler(args)
        except (LinkageError, argparse.ArgumentError, argparse.ArgumentTypeError) as exc:  # the user's input
            for line in error_lines(exc):
                note("error", line)
            return EXIT_INPUT
        except BrokenPipeError:  # e.g. `linkage analyze ... | head`: the reader left, not an error
            try:
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, sys.stdout.fileno())
            except (OSError, ValueError, AttributeError):
                pass
            return 0
        except OSError as exc:  # a file or folder the user named cannot be read or written
            where = f"{exc.filename}: " if exc.filename else ""
            note("error", f"{where}cannot be read or written ({exc.strerror or exc})")
            return EXIT_INPUT
        except Exception as exc:  # a bug of the library: one line, no traceback
            note("error", f"internal error ({type(exc).__name__}: {exc}); please report it with the "
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
            note("warning", str(w.message))
    if numerical:
        note("warning", NUMERICAL_WARNING)
