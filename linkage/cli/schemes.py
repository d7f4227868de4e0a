"""``linkage schemes``: the shipped schemes, one line each (name, structural formula, description)."""

from __future__ import annotations

import argparse

from ..errors import LinkageError
from ..model.scheme import load, shipped_schemes
from ..structure import structure_of
from .options import EXIT_INPUT, error_lines, note, out


def add(sub) -> None:
    p = sub.add_parser("schemes", help="list the shipped schemes",
                       description="List the schemes shipped with the library: name, structural "
                                   "formula, description.")
    p.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    rows, status = [], 0
    for name in shipped_schemes():
        try:
            mech = load(name)
            rows.append((name, structure_of(mech).formula, mech.description))
        except LinkageError as exc:  # a broken shipped file must not hide the others
            for line in error_lines(exc):
                note("error", line)
            rows.append((name, "?", "(cannot be loaded, see the error above)"))
            status = EXIT_INPUT
    if rows:
        w_name = max(len(r[0]) for r in rows)
        w_formula = max(len(r[1]) for r in rows)
        out("\n".join(f"{n.ljust(w_name)}  {f.ljust(w_formula)}  {d}".rstrip() for n, f, d in rows))
    return status
