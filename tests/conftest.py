"""Shared fixtures: what several test files check is generated once per session.

The slowest things the suite makes (a report folder, a set of course variants, an example's
pictures) are each made by one command. Tests that check different things of the same output
ask for it through these fixtures, so the command runs once: ``linkage_run`` runs a ``linkage``
command line in its own folder and keeps the result by its arguments; ``example_run`` runs an
example script in its own folder and keeps the result by the script.
"""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Run:
    """One run of a command: its exit status, what it printed, and the folder it ran in."""

    status: int
    out: str
    err: str
    cwd: Path


@pytest.fixture(scope="session")
def linkage_run(tmp_path_factory):
    """``linkage_run(*argv) -> Run``: ``linkage ARGV`` run once per distinct ``argv`` in a folder
    of its own (relative paths in ``argv``, like ``--out report``, land there)."""
    from linkage.cli import main

    done: dict[tuple[str, ...], Run] = {}

    def run(*argv: str) -> Run:
        key = tuple(str(a) for a in argv)
        if key not in done:
            cwd = tmp_path_factory.mktemp("linkage_run")
            out, err, here = io.StringIO(), io.StringIO(), os.getcwd()
            try:
                os.chdir(cwd)
                with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                    status = main(list(key))
            finally:
                os.chdir(here)
            done[key] = Run(status, out.getvalue(), err.getvalue(), cwd)
        return done[key]

    return run


@pytest.fixture(scope="session")
def example_run(tmp_path_factory):
    """``example_run(script) -> Run``: the example ``script`` (a path in examples/) run once, in a
    fresh Python with the Agg backend, writing into a folder of its own (``Run.cwd``)."""
    done: dict[Path, Run] = {}

    def run(script: Path) -> Run:
        if script not in done:
            folder = tmp_path_factory.mktemp(script.stem)
            env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT))
            result = subprocess.run([sys.executable, str(script), str(folder)], cwd=ROOT, env=env,
                                    capture_output=True, text=True, timeout=300)
            done[script] = Run(result.returncode, result.stdout, result.stderr, folder)
        return done[script]

    return run
