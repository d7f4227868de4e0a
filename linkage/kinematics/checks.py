"""What loading a scheme checks of its motion: the mechanism decomposes into groups, their
assembly conditions tell the modes apart, and a declared input range assembles everywhere.

Registered with :func:`linkage.model.scheme.register_check`, so that :func:`linkage.load` refuses
such a scheme naming the key and the value; reads the structure and the motion.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from assur.base import CANNOT_ASSEMBLE, NOT_CONVERGED

from ..errors import LinkageError, SchemeError
from ..model.mechanism import Mechanism
from ..model.scheme import register_check
from ..structure import structure_of
from .assembly import assembly_branches
from .motion import analyze, input_sweep

__all__ = ["check_motion"]


def check_motion(mech: Mechanism, data: Mapping[str, Any]) -> None:
    """SchemeError when ``mech`` does not decompose, a group never assembles or its assembly
    condition does not tell its modes apart, or the declared range does not assemble."""
    try:
        structure_of(mech)
        assembly_branches(mech)
    except SchemeError:
        raise
    except LinkageError as exc:  # a wrong mobility, a group that never assembles ...
        raise SchemeError(str(exc)) from None
    if mech.input_range is not None:
        _check_range_assembles(mech, data)


def _check_range_assembles(mech: Mechanism, data: Mapping[str, Any]) -> None:
    """SchemeError naming the key, its value and the input angles of the declared range at which
    the mechanism cannot be assembled (a range is where it assembles)."""
    motion = input_sweep(mech)
    phi = motion.phi
    if np.any(motion.status == NOT_CONVERGED):   # a solver failure, not the range's: say so (ConvergenceError)
        try:
            analyze(mech, phi[motion.status == NOT_CONVERGED], order=0)
        except LinkageError as exc:
            raise SchemeError(str(exc)) from None
    bad = np.flatnonzero(motion.status == CANNOT_ASSEMBLE)
    if not len(bad):
        return
    key = "range_deg" if "range_deg" in data else "range"
    coordinate = mech.coordinate
    deg, unit = coordinate.shown(phi), coordinate.shown_unit
    ok = np.flatnonzero(motion.status != CANNOT_ASSEMBLE)
    runs = _runs(deg, bad)
    assembles = f"; it assembles at {_runs(deg, ok)} {unit}" if len(ok) else "; it assembles nowhere in it"
    raise SchemeError(f"{key} = {data[key]!r}: the mechanism cannot be assembled at {coordinate.symbol} = {runs} "
                      f"{unit} of this range{assembles} (checked at {len(phi)} positions): declare a range within "
                      "which it assembles")


def _runs(deg, index) -> str:
    """Consecutive sweep indices as ``a..b`` angle spans (deg), joined by commas."""
    spans, start = [], index[0]
    for prev, cur in zip(index, list(index[1:]) + [None]):
        if cur is None or cur != prev + 1:
            lo, hi = deg[start], deg[prev]
            spans.append(f"{lo:.4g}" if start == prev else f"{lo:.4g}..{hi:.4g}")
            start = cur
    return ", ".join(spans)


register_check(check_motion)
