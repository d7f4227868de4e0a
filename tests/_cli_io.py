"""Shared helpers of the CLI tests: run ``linkage`` in-process and read its outputs back."""

import csv
import io

import numpy as np

from linkage.cli import main


def run(capsys, *argv):
    """Exit code, stdout and stderr of ``linkage *argv``."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def read_csv(text):
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    data = np.array([[float(x) for x in r] for r in body])
    return {name: data[:, k] for k, name in enumerate(header)}


def read_table(text):
    """The columns of a table for people: the names line, then (skipped) the line of units in
    brackets, then the rows."""
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#") and "[" not in ln]
    header = lines[0].split()
    data = np.array([[float(x) for x in ln.split()] for ln in lines[1:]])
    return {name: data[:, k] for k, name in enumerate(header)}
